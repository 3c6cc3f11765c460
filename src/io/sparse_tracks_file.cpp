// Copyright wild_mvs authors.
#include "wild_mvs/io/sparse_tracks_file.h"

#include <cmath>
#include <fstream>
#include <limits>
#include <locale>
#include <sstream>

#include "wild_mvs/core/error.h"
#include "wild_mvs/io/atomic_file.h"

namespace wild_mvs {
namespace {

const char kHeader[] = "# wild_mvs sparse tracks v1";

// "KEY VALUE" -> the key.
std::string KeyOf(const std::string& line) {
  return line.substr(0, line.find(' '));
}

}  // namespace

void WriteSparseTracks(const std::string& path, const Scene& scene,
                       const std::vector<std::string>& fingerprint) {
  WriteFileAtomically(path, [&](std::ostream& os) {
    os.imbue(std::locale::classic());
    os.precision(std::numeric_limits<double>::max_digits10);
    os << kHeader
       << " (exact; read back by 'wild_mvs reconstruct' on this folder)\n";
    for (const std::string& f : fingerprint) os << "option " << f << "\n";
    for (const View& v : scene.views) {
      os << "view " << v.camera.width << " " << v.camera.height << " " << v.name
         << "\n";
    }
    os << "points " << scene.points.size() << "\n";
    for (const SparsePoint& p : scene.points) {
      os << "point " << p.xyz.x() << " " << p.xyz.y() << " " << p.xyz.z() << " "
         << static_cast<double>(p.rgb.x()) << " "
         << static_cast<double>(p.rgb.y()) << " "
         << static_cast<double>(p.rgb.z()) << " " << p.error << " "
         << p.track.size() << "\n";
      for (const Observation& o : p.track) {
        os << "obs " << o.view << " " << o.xy.x() << " " << o.xy.y() << " "
           << o.scale << "\n";
      }
    }
    os << "end\n";
  });
}

bool ReadSparseTracks(const std::string& path, const Scene& scene,
                      const std::vector<std::string>& fingerprint,
                      std::vector<SparsePoint>* points, std::string* why) {
  std::ifstream in(path);
  Require(static_cast<bool>(in), path, ": cannot read");
  std::string line;
  int n = 0;
  auto fail = [&](const std::string& what) {
    throw Error(Msg(path, ":", n, ": ", what));
  };
  auto next = [&]() {
    if (!std::getline(in, line)) fail("unexpected end of file");
    ++n;
  };
  next();
  if (line.rfind(kHeader, 0) != 0) {
    fail(Msg("not a wild_mvs tracks file (expected '", kHeader, "')"));
  }
  // Options and views: compared with this run's.
  size_t option = 0, view = 0;
  for (next(); line.rfind("points ", 0) != 0; next()) {
    if (line.rfind("option ", 0) == 0) {
      const std::string f = line.substr(7);
      const auto wanted = [&](const std::string& key) {
        for (const std::string& g : fingerprint) {
          if (KeyOf(g) == key) return g;
        }
        return std::string();
      };
      const std::string now = wanted(KeyOf(f));
      if (now != f) {
        *why = Msg("option ", KeyOf(f), ": '", f.substr(f.find(' ') + 1),
                   "' in the file, ",
                   now.empty() ? std::string("unknown now")
                               : "'" + now.substr(now.find(' ') + 1) + "' now");
        return false;
      }
      ++option;
    } else if (line.rfind("view ", 0) == 0) {
      std::istringstream ss(line.substr(5));
      int w = 0, h = 0;
      ss >> w >> h;
      std::string name;
      std::getline(ss, name);
      if (!ss && !ss.eof()) fail("bad view line");
      if (!name.empty() && name[0] == ' ') name.erase(0, 1);
      if (view >= scene.views.size()) {
        *why = Msg("the file has more views than the dataset (",
                   scene.views.size(), ")");
        return false;
      }
      const View& v = scene.views[view];
      if (v.name != name || v.camera.width != w || v.camera.height != h) {
        *why = Msg("view ", view + 1, " is '", name, "' ", w, "x", h,
                   " in the file, '", v.name, "' ", v.camera.width, "x",
                   v.camera.height, " now");
        return false;
      }
      ++view;
    } else {
      fail(Msg("unexpected line '", line.substr(0, 40), "'"));
    }
  }
  if (option != fingerprint.size()) {
    *why = Msg("the file records ", option, " options, this run ",
               fingerprint.size());
    return false;
  }
  if (view != scene.views.size()) {
    *why =
        Msg("the file has ", view, " views, the dataset ", scene.views.size());
    return false;
  }
  long long count = -1;
  {
    std::istringstream ss(line.substr(7));
    ss >> count;
    if (!ss || count < 0) fail("bad point count");
  }
  std::vector<SparsePoint> result;
  // No reserve(count): a corrupt count must not allocate; the lines do.
  for (long long i = 0; i < count; ++i) {
    next();
    std::istringstream ss(line);
    ss.imbue(std::locale::classic());
    std::string tag;
    SparsePoint p;
    double r, g, b;
    long long obs = -1;
    ss >> tag >> p.xyz.x() >> p.xyz.y() >> p.xyz.z() >> r >> g >> b >>
        p.error >> obs;
    if (!ss || tag != "point" || obs < 0 || !p.xyz.allFinite()) {
      fail("bad point line");
    }
    p.rgb = Eigen::Vector3f(static_cast<float>(r), static_cast<float>(g),
                            static_cast<float>(b));
    // A colour beyond float's range would be written back as "inf".
    if (!p.rgb.allFinite()) fail("bad point line (colour out of range)");
    for (long long j = 0; j < obs; ++j) {
      next();
      std::istringstream os(line);
      os.imbue(std::locale::classic());
      Observation o;
      os >> tag >> o.view >> o.xy.x() >> o.xy.y() >> o.scale;
      if (!os || tag != "obs" || o.view < 0 ||
          o.view >= static_cast<int>(scene.views.size())) {
        fail("bad observation line");
      }
      p.track.push_back(o);
    }
    result.push_back(std::move(p));
  }
  next();
  if (line != "end") fail("expected 'end' (file truncated?)");
  *points = std::move(result);
  return true;
}

}  // namespace wild_mvs
