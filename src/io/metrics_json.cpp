// Copyright wild_mvs authors.
#include "wild_mvs/io/metrics_json.h"

#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

namespace wild_mvs {
namespace {

// Number formatting: 9 significant digits, inf / nan -> null.
std::string Num(double v) {
  if (!std::isfinite(v)) return "null";
  char buf[40];
  std::snprintf(buf, sizeof(buf), "%.9g", v);
  return buf;
}

std::string JsonArray(const std::vector<double>& v) {
  std::string s = "[";
  for (size_t k = 0; k < v.size(); ++k) {
    if (k) s += ", ";
    s += Num(v[k]);
  }
  return s + "]";
}

}  // namespace

std::string DepthMetricsJson(const DepthMetrics& m) {
  std::string s = "{";
  s += "\"gt_valid\": " + std::to_string(m.gt_valid);
  s += ", \"estimated\": " + std::to_string(m.estimated);
  s += ", \"evaluated\": " + std::to_string(m.evaluated);
  s += ", \"outside_gt\": " + std::to_string(m.outside_gt);
  s += ", \"completeness\": " + Num(m.completeness);
  s += ", \"median_abs_error\": " + Num(m.median_abs_error);
  s += ", \"median_rel_error\": " + Num(m.median_rel_error);
  s += ", \"mean_abs_error\": " + Num(m.mean_abs_error);
  s += ", \"rmse\": " + Num(m.rmse);
  s += ", \"relative_thresholds\": " + JsonArray(m.relative_thresholds);
  s += ", \"relative_accuracy\": " + JsonArray(m.relative_accuracy);
  s += ", \"relative_completeness\": " + JsonArray(m.relative_completeness);
  s += ", \"absolute_thresholds\": " + JsonArray(m.absolute_thresholds);
  s += ", \"absolute_accuracy\": " + JsonArray(m.absolute_accuracy);
  s += ", \"absolute_completeness\": " + JsonArray(m.absolute_completeness);
  return s + "}";
}

std::string CloudMetricsJson(const CloudMetrics& m) {
  std::string s = "{";
  s += "\"reconstruction_points\": " + std::to_string(m.reconstruction_points);
  s += ", \"gt_points\": " + std::to_string(m.gt_points);
  s += ", \"accuracy\": " + Num(m.accuracy);
  s += ", \"accuracy_fraction\": " + Num(m.accuracy_fraction);
  s += ", \"completeness_distance\": " + Num(m.completeness_distance);
  s += ", \"mean_accuracy\": " + Num(m.mean_accuracy);
  s += ", \"median_accuracy\": " + Num(m.median_accuracy);
  s += ", \"mean_completeness\": " + Num(m.mean_completeness);
  s += ", \"median_completeness\": " + Num(m.median_completeness);
  s += ", \"taus\": " + JsonArray(m.taus);
  s += ", \"precision\": " + JsonArray(m.precision);
  s += ", \"recall\": " + JsonArray(m.recall);
  s += ", \"completeness\": " + JsonArray(m.recall);
  s += ", \"fscore\": " + JsonArray(m.fscore);
  return s + "}";
}

}  // namespace wild_mvs
