// Copyright wild_mvs authors.
#include "wild_mvs/io/report_json.h"

#include <cmath>
#include <cstdio>
#include <sstream>

namespace wild_mvs {
namespace {

std::string JsonEscape(const std::string& s) {
  std::string o;
  for (char c : s) {
    switch (c) {
      case '"':
        o += "\\\"";
        break;
      case '\\':
        o += "\\\\";
        break;
      case '\n':
        o += "\\n";
        break;
      case '\t':
        o += "\\t";
        break;
      default:
        if (static_cast<unsigned char>(c) < 0x20) {
          char buf[8];
          snprintf(buf, sizeof(buf), "\\u%04x", c);
          o += buf;
        } else {
          o += c;
        }
    }
  }
  return o;
}

std::string JsonNumber(double v) {
  if (!std::isfinite(v)) return "null";
  std::ostringstream os;
  os.precision(10);
  os << v;
  return os.str();
}

}  // namespace

std::string ViewReportJson(const ViewReport& r, const Scene& scene) {
  std::ostringstream os;
  auto name = [&](int v) {
    return (v >= 0 && v < static_cast<int>(scene.views.size()))
               ? scene.views[v].name
               : std::string("?");
  };
  os << "{\n  \"neighbors\": [";
  for (size_t i = 0; i < r.neighbors.size(); ++i) {
    os << (i ? ", " : "") << "{\"view\": \"" << JsonEscape(name(r.neighbors[i]))
       << "\", \"score\": "
       << JsonNumber(i < r.neighbor_scores.size() ? r.neighbor_scores[i] : 0)
       << ", \"scale\": " << JsonNumber(i < r.scales.size() ? r.scales[i] : 0)
       << "}";
  }
  os << "],\n  \"working_scale\": " << JsonNumber(r.working_scale)
     << ",\n  \"width\": " << r.width << ",\n  \"height\": " << r.height
     << ",\n  \"seeds_tried\": " << r.seeds_tried
     << ",\n  \"seeds_accepted\": " << r.seeds_accepted
     << ",\n  \"samples\": " << r.samples
     << ",\n  \"planar_samples\": " << r.planar_samples
     << ",\n  \"coarse_samples\": " << r.coarse_samples
     << ",\n  \"pixel_visits\": " << r.pixel_visits << ",\n  \"fallbacks\": [";
  for (size_t i = 0; i < r.fallbacks.size(); ++i)
    os << (i ? ", " : "") << "\"" << JsonEscape(r.fallbacks[i]) << "\"";
  os << "],\n  \"seconds\": " << JsonNumber(r.seconds)
     << ",\n  \"cpu_seconds\": " << JsonNumber(r.cpu_seconds) << "\n}\n";
  return os.str();
}

}  // namespace wild_mvs
