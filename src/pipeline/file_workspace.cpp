// Copyright wild_mvs authors.
#include "wild_mvs/pipeline/file_workspace.h"

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>

#include "wild_mvs/core/error.h"
#include "wild_mvs/io/atomic_file.h"
#include "wild_mvs/io/depth_map_io.h"
#include "wild_mvs/io/report_json.h"

namespace wild_mvs {
namespace {

namespace fs = std::filesystem;

std::string LogPath(const std::string& dir, const std::string& stem) {
  return dir + "/log/" + stem + ".json";
}

std::string JsonString(const std::string& s) {
  std::string o = "\"";
  for (char c : s) {
    if (c == '"' || c == '\\') {
      o += '\\';
      o += c;
    } else if (static_cast<unsigned char>(c) < 0x20) {
      char buf[8];
      std::snprintf(buf, sizeof(buf), "\\u%04x", c);
      o += buf;
    } else {
      o += c;
    }
  }
  return o + "\"";
}

std::string ReadText(const std::string& path) {
  std::ifstream in(path);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

// The view log's body without the "view"/"stem" members the writer adds
// (so that a raw log can be rewritten with more members).
std::string StripViewHeader(const std::string& json) {
  static const std::regex re(
      "^\\{\\n  \"view\": \"(?:[^\"\\\\]|\\\\.)*\",\\n  \"stem\": "
      "\"(?:[^\"\\\\]|\\\\.)*\",");
  return std::regex_replace(json, re, "{",
                            std::regex_constants::format_first_only);
}

// Writes one view's maps and its log (the log last: the view is complete
// once it exists). extra: more members for the log ("" = none).
void WriteViewOutputs(const View& view, const std::string& dir,
                      const DepthMap& map,
                      const std::vector<std::string>& neighbor_names,
                      const std::string& json_body, const std::string& extra) {
  WriteDepthMapFiles(dir, view.Stem(), map, neighbor_names, true);
  std::string json = json_body;
  if (json.rfind("{\n", 0) == 0) {
    json = "{\n  \"view\": " + JsonString(view.name) +
           ",\n  \"stem\": " + JsonString(view.Stem()) + "," + extra +
           json.substr(1);
  }
  WriteFileAtomically(LogPath(dir, view.Stem()),
                      [&](std::ostream& os) { os << json; });
}

}  // namespace

bool ViewOutputsComplete(const std::string& dir, const std::string& stem) {
  std::error_code ec;
  return DepthMapFilesExist(dir, stem) &&
         fs::is_regular_file(LogPath(dir, stem), ec);
}

FileDepthWorkspace::FileDepthWorkspace(const Scene& scene, std::string out,
                                       bool filter)
    : scene_(scene), out_(std::move(out)), raw_(filter ? out_ + "/raw" : out_) {
  for (size_t i = 0; i < scene_.views.size(); ++i)
    index_.emplace(scene_.views[i].name, static_cast<int>(i));
}

const std::string& FileDepthWorkspace::Folder(Stage stage) const {
  return stage == Stage::kRaw ? raw_ : out_;
}

bool FileDepthWorkspace::Has(Stage stage, int key) const {
  Require(key >= 0 && key < static_cast<int>(scene_.views.size()), "view ", key,
          " is not in the scene");
  return ViewOutputsComplete(Folder(stage), scene_.views[key].Stem());
}

std::shared_ptr<const DepthMap> FileDepthWorkspace::Read(Stage stage,
                                                         int key) const {
  Require(key >= 0 && key < static_cast<int>(scene_.views.size()), "view ", key,
          " is not in the scene");
  DepthMapFiles files =
      ReadDepthMapFiles(Folder(stage), scene_.views[key].Stem());
  auto map = std::make_shared<DepthMap>(std::move(files.map));
  map->view = key;
  for (const std::string& name : files.neighbor_names) {
    auto it = index_.find(name);
    if (it != index_.end()) map->neighbors.push_back(it->second);
  }
  return map;
}

void FileDepthWorkspace::Write(Stage stage, int key, const ViewResult& result) {
  Require(key >= 0 && key < static_cast<int>(scene_.views.size()), "view ", key,
          " is not in the scene");
  const View& view = scene_.views[key];
  std::vector<std::string> names;
  for (int n : result.map.neighbors) {
    if (n >= 0 && n < static_cast<int>(scene_.views.size())) {
      names.push_back(scene_.views[n].name);
    }
  }
  if (stage == Stage::kRaw || !result.filtered) {
    WriteViewOutputs(view, Folder(stage), result.map, names,
                     ViewReportJson(result.report, scene_), "");
    return;
  }
  const std::string extra = Msg(
      "\n  \"consistency\": {\"samples_before\": ", result.consistency.samples,
      ", \"kept\": ", result.consistency.kept,
      ", \"neighbor_maps\": ", result.neighbor_maps, "},");
  // The raw log with the filtered count as its "samples" (written once:
  // the log marks the view complete).
  static const std::regex samples_re("\"samples\": [0-9]+");
  const std::string body = std::regex_replace(
      StripViewHeader(ReadText(LogPath(raw_, view.Stem()))), samples_re,
      Msg("\"samples\": ", result.consistency.kept),
      std::regex_constants::format_first_only);
  WriteViewOutputs(view, out_, result.map, names, body, extra);
}

long long FileDepthWorkspace::Samples(Stage stage, int key) const {
  const std::string text =
      ReadText(LogPath(Folder(stage), scene_.views.at(key).Stem()));
  std::smatch m;
  static const std::regex re("\"samples\"\\s*:\\s*([0-9]+)");
  if (!std::regex_search(text, m, re)) return -1;
  return std::stoll(m[1].str());
}

}  // namespace wild_mvs
