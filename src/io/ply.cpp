// Copyright wild_mvs authors.
#include "wild_mvs/io/ply.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <sstream>

#include "text_util.h"
#include "wild_mvs/core/error.h"
#include "wild_mvs/io/atomic_file.h"

namespace wild_mvs {
namespace {

// ----------------------------------------------------------------- writing
template <typename T>
void Put(std::string* s, T v) {
  s->append(reinterpret_cast<const char*>(&v), sizeof(T));
}

void CheckCloud(const std::string& path, const PointCloud& c) {
  const size_t n = c.size();
  Require(c.normal.empty() || c.normal.size() == n, path, ": cloud has ",
          c.normal.size(), " normals for ", n, " points");
  Require(c.rgb.empty() || c.rgb.size() == n, path, ": cloud has ",
          c.rgb.size(), " colours for ", n, " points");
  Require(c.confidence.empty() || c.confidence.size() == n, path,
          ": cloud has ", c.confidence.size(), " confidences for ", n,
          " points");
  Require(c.support.empty() || c.support.size() == n, path, ": cloud has ",
          c.support.size(), " support values for ", n, " points");
}

// The header of a binary PLY of n vertices with c's attributes (+ faces).
std::string Header(size_t n, const PointCloud& c, const size_t* faces) {
  std::ostringstream h;
  h << "ply\nformat binary_little_endian 1.0\ncomment written by wild_mvs\n"
    << "element vertex " << n << "\n"
    << "property float x\nproperty float y\nproperty float z\n";
  if (c.has_normal())
    h << "property float nx\nproperty float ny\nproperty float nz\n";
  if (c.has_rgb())
    h << "property uchar red\nproperty uchar green\nproperty uchar blue\n";
  if (c.has_confidence()) h << "property float confidence\n";
  if (c.has_support()) h << "property ushort support\n";
  if (faces)
    h << "element face " << *faces << "\n"
      << "property list uchar int vertex_indices\n";
  h << "end_header\n";
  return h.str();
}

constexpr size_t kFlushBytes = size_t{1} << 21;

// Appends c's vertices to buf, writing buf to os whenever it exceeds
// kFlushBytes.
void PutVertices(const PointCloud& c, std::string* buf, std::ostream& os) {
  for (size_t i = 0; i < c.size(); ++i) {
    for (int k = 0; k < 3; ++k) Put<float>(buf, c.xyz[i][k]);
    if (c.has_normal())
      for (int k = 0; k < 3; ++k) Put<float>(buf, c.normal[i][k]);
    if (c.has_rgb())
      for (int k = 0; k < 3; ++k) {
        const float v = c.rgb[i][k];
        Put<uint8_t>(
            buf, static_cast<uint8_t>(std::lround(
                     std::clamp(std::isfinite(v) ? v : 0.f, 0.f, 1.f) * 255)));
      }
    if (c.has_confidence()) Put<float>(buf, c.confidence[i]);
    if (c.has_support()) Put<uint16_t>(buf, c.support[i]);
    if (buf->size() > kFlushBytes) {
      os.write(buf->data(), static_cast<std::streamsize>(buf->size()));
      buf->clear();
    }
  }
}

void Write(const std::string& path, const PointCloud& c,
           const std::vector<Eigen::Vector3i>* faces) {
  CheckCloud(path, c);
  const size_t n = c.size();
  if (faces)
    for (const auto& f : *faces)
      Require(f.minCoeff() >= 0 && static_cast<size_t>(f.maxCoeff()) < n, path,
              ": face (", f.transpose(), ") refers to a missing vertex (", n,
              " vertices)");
  const size_t nf = faces ? faces->size() : 0;
  const std::string header = Header(n, c, faces ? &nf : nullptr);
  WriteFileAtomically(path, [&](std::ostream& os) {
    os.write(header.data(), static_cast<std::streamsize>(header.size()));
    std::string buf;
    buf.reserve(kFlushBytes + 64);
    PutVertices(c, &buf, os);
    if (faces)
      for (const auto& f : *faces) {
        Put<uint8_t>(&buf, 3);
        for (int k = 0; k < 3; ++k) Put<int32_t>(&buf, f[k]);
        if (buf.size() > kFlushBytes) {
          os.write(buf.data(), static_cast<std::streamsize>(buf.size()));
          buf.clear();
        }
      }
    os.write(buf.data(), static_cast<std::streamsize>(buf.size()));
  });
}

// ----------------------------------------------------------------- reading
enum class Type { kI8, kU8, kI16, kU16, kI32, kU32, kF32, kF64 };

bool ParseType(const std::string& s, Type* t) {
  static const std::pair<const char*, Type> table[] = {
      {"char", Type::kI8},    {"int8", Type::kI8},     {"uchar", Type::kU8},
      {"uint8", Type::kU8},   {"short", Type::kI16},   {"int16", Type::kI16},
      {"ushort", Type::kU16}, {"uint16", Type::kU16},  {"int", Type::kI32},
      {"int32", Type::kI32},  {"uint", Type::kU32},    {"uint32", Type::kU32},
      {"float", Type::kF32},  {"float32", Type::kF32}, {"double", Type::kF64},
      {"float64", Type::kF64}};
  for (const auto& [name, type] : table)
    if (s == name) {
      *t = type;
      return true;
    }
  return false;
}

size_t SizeOf(Type t) {
  switch (t) {
    case Type::kI8:
    case Type::kU8:
      return 1;
    case Type::kI16:
    case Type::kU16:
      return 2;
    case Type::kI32:
    case Type::kU32:
    case Type::kF32:
      return 4;
    case Type::kF64:
      return 8;
  }
  return 1;
}

// Scale that maps an integer colour type to [0, 1].
double ColourScale(Type t) {
  switch (t) {
    case Type::kU8:
    case Type::kI8:
      return 1.0 / 255;
    case Type::kU16:
    case Type::kI16:
      return 1.0 / 65535;
    case Type::kU32:
    case Type::kI32:
      return 1.0 / 4294967295.0;
    default:
      return 1.0;
  }
}

struct Property {
  std::string name;
  Type type = Type::kF32;
  bool is_list = false;
  Type count_type = Type::kU8;
};
struct Element {
  std::string name;
  uint64_t count = 0;
  std::vector<Property> props;
  std::string where;  // header line
};

enum class Format { kAscii, kLittle, kBig };

class Body {
 public:
  Body(const std::string& data, size_t pos, Format f, const std::string& path)
      : d_(data), pos_(pos), f_(f), path_(path) {}

  double Read(Type t, const char* what) {
    if (f_ == Format::kAscii) return ReadAscii(t, what);
    const size_t n = SizeOf(t);
    if (d_.size() - pos_ < n)
      throw Error(Msg(path_, ": truncated file: cannot read ", what,
                      " at byte ", pos_));
    unsigned char b[8];
    std::memcpy(b, d_.data() + pos_, n);
    pos_ += n;
    if (f_ == Format::kBig) std::reverse(b, b + n);
    switch (t) {
      case Type::kI8: {
        int8_t v;
        std::memcpy(&v, b, 1);
        return v;
      }
      case Type::kU8:
        return b[0];
      case Type::kI16: {
        int16_t v;
        std::memcpy(&v, b, 2);
        return v;
      }
      case Type::kU16: {
        uint16_t v;
        std::memcpy(&v, b, 2);
        return v;
      }
      case Type::kI32: {
        int32_t v;
        std::memcpy(&v, b, 4);
        return v;
      }
      case Type::kU32: {
        uint32_t v;
        std::memcpy(&v, b, 4);
        return v;
      }
      case Type::kF32: {
        float v;
        std::memcpy(&v, b, 4);
        return v;
      }
      case Type::kF64: {
        double v;
        std::memcpy(&v, b, 8);
        return v;
      }
    }
    return 0;
  }
  size_t remaining() const { return d_.size() - pos_; }
  size_t pos() const { return pos_; }
  bool ascii() const { return f_ == Format::kAscii; }
  // Line number (ascii) for messages.
  int Line() const { return line_; }
  void SetLine(int line) { line_ = line; }

 private:
  double ReadAscii(Type t, const char* what) {
    while (pos_ < d_.size() &&
           std::isspace(static_cast<unsigned char>(d_[pos_]))) {
      if (d_[pos_] == '\n') ++line_;
      ++pos_;
    }
    if (pos_ >= d_.size())
      throw Error(
          Msg(path_, " line ", Line(), ": truncated file: cannot read ", what));
    size_t e = pos_;
    while (e < d_.size() && !std::isspace(static_cast<unsigned char>(d_[e])))
      ++e;
    const std::string tok = d_.substr(pos_, e - pos_);
    pos_ = e;
    char* end = nullptr;
    const bool is_float = t == Type::kF32 || t == Type::kF64;
    const double v =
        is_float ? std::strtod(tok.c_str(), &end)
                 : static_cast<double>(std::strtoll(tok.c_str(), &end, 10));
    if (end == tok.c_str() || *end != '\0')
      throw Error(Msg(path_, " line ", line_, ": ", what, " '", tok,
                      "' is not ", is_float ? "a number" : "an integer"));
    return v;
  }

  const std::string& d_;
  size_t pos_;
  Format f_;
  std::string path_;
  int line_ = 1;
};

Mesh Read(const std::string& path, bool want_faces) {
  const std::string d = io_detail::ReadWholeFile(path);
  // Header.
  size_t pos = 0;
  int line_no = 0;
  auto next_line = [&](std::string* line) {
    if (pos >= d.size()) return false;
    size_t e = d.find('\n', pos);
    if (e == std::string::npos) e = d.size();
    *line = d.substr(pos, e - pos);
    if (!line->empty() && line->back() == '\r') line->pop_back();
    pos = std::min(d.size(), e + 1);
    ++line_no;
    return true;
  };
  std::string line;
  Require(next_line(&line) && line == "ply", path,
          ": not a PLY file (first line must be 'ply')");
  Format format = Format::kAscii;
  bool have_format = false, ended = false;
  std::vector<Element> elements;
  while (next_line(&line)) {
    const std::string where = Msg(path, " line ", line_no);
    const auto tok = io_detail::Split(line);
    if (tok.empty() || tok[0] == "comment" || tok[0] == "obj_info") continue;
    if (tok[0] == "end_header") {
      ended = true;
      break;
    }
    if (tok[0] == "format") {
      io_detail::RequireTokens(tok, 3, true, where, "format line");
      if (tok[1] == "ascii")
        format = Format::kAscii;
      else if (tok[1] == "binary_little_endian")
        format = Format::kLittle;
      else if (tok[1] == "binary_big_endian")
        format = Format::kBig;
      else
        throw Error(Msg(where, ": unknown PLY format '", tok[1], "'"));
      have_format = true;
    } else if (tok[0] == "element") {
      io_detail::RequireTokens(tok, 3, true, where, "element line");
      const long long n = io_detail::ParseInt(tok[2], where, "element count");
      Require(n >= 0, where, ": negative element count ", n);
      elements.push_back({tok[1], static_cast<uint64_t>(n), {}, where});
    } else if (tok[0] == "property") {
      Require(!elements.empty(), where, ": property before any element");
      Property p;
      if (tok.size() >= 2 && tok[1] == "list") {
        io_detail::RequireTokens(tok, 5, true, where, "list property");
        p.is_list = true;
        Require(ParseType(tok[2], &p.count_type) && ParseType(tok[3], &p.type),
                where, ": unknown property type in '", line, "'");
        Require(p.count_type != Type::kF32 && p.count_type != Type::kF64, where,
                ": list count type must be an integer");
        p.name = tok[4];
      } else {
        io_detail::RequireTokens(tok, 3, true, where, "property");
        Require(ParseType(tok[1], &p.type), where, ": unknown property type '",
                tok[1], "'");
        p.name = tok[2];
      }
      elements.back().props.push_back(p);
    } else {
      throw Error(Msg(where, ": unknown header keyword '", tok[0], "'"));
    }
  }
  Require(ended, path, ": truncated PLY header (no end_header)");
  Require(have_format, path, ": PLY header has no format line");

  Mesh mesh;
  PointCloud& c = mesh.vertices;
  Body body(d, pos, format, path);
  body.SetLine(line_no + 1);
  bool have_vertex = false;
  for (const Element& el : elements) {
    // Minimum bytes per element instance (lists: at least their count).
    size_t min_bytes = 0;
    for (const Property& p : el.props)
      min_bytes += p.is_list ? SizeOf(p.count_type) : SizeOf(p.type);
    // ASCII: each value takes at least one character and one separator
    // (the very last one may lack its separator).
    if (body.ascii()) min_bytes = el.props.empty() ? 0 : 2 * el.props.size();
    if (min_bytes > 0 && el.count > (body.remaining() + 1) / min_bytes)
      throw Error(Msg(el.where, ": element '", el.name, "' count ", el.count,
                      " does not fit in the remaining ", body.remaining(),
                      " bytes (corrupt or truncated file)"));
    const bool is_vertex = el.name == "vertex";
    const bool is_face = el.name == "face";
    if (is_vertex) {
      Require(!have_vertex, el.where, ": two vertex elements");
      have_vertex = true;
    }
    // Map vertex properties to fields: 0-2 xyz, 3-5 normal, 6-8 rgb,
    // 9 confidence, 10 support, -1 skip.
    std::vector<int> field(el.props.size(), -1);
    int face_list = -1;
    bool has[11] = {false};
    for (size_t k = 0; k < el.props.size(); ++k) {
      const std::string& n = el.props[k].name;
      if (is_vertex && !el.props[k].is_list) {
        static const std::vector<std::pair<std::vector<std::string>, int>> map =
            {{{"x"}, 0},
             {{"y"}, 1},
             {{"z"}, 2},
             {{"nx", "normal_x"}, 3},
             {{"ny", "normal_y"}, 4},
             {{"nz", "normal_z"}, 5},
             {{"red", "r", "diffuse_red"}, 6},
             {{"green", "g", "diffuse_green"}, 7},
             {{"blue", "b", "diffuse_blue"}, 8},
             {{"confidence"}, 9},
             {{"support"}, 10}};
        for (const auto& [names, f] : map)
          if (std::find(names.begin(), names.end(), n) != names.end() &&
              !has[f]) {
            field[k] = f;
            has[f] = true;
          }
      }
      if (is_face && el.props[k].is_list &&
          (n == "vertex_indices" || n == "vertex_index") && face_list < 0)
        face_list = static_cast<int>(k);
    }
    if (is_vertex) {
      Require(has[0] && has[1] && has[2], el.where,
              ": vertex element lacks x, y or z");
      const size_t n = el.count;
      c.xyz.resize(n);
      if (has[3] && has[4] && has[5]) c.normal.resize(n);
      if (has[6] && has[7] && has[8]) c.rgb.resize(n);
      if (has[9]) c.confidence.resize(n);
      if (has[10]) c.support.resize(n);
    }
    for (uint64_t i = 0; i < el.count; ++i) {
      for (size_t k = 0; k < el.props.size(); ++k) {
        const Property& p = el.props[k];
        if (p.is_list) {
          const double cnt = body.Read(p.count_type, "list count");
          Require(cnt >= 0 && cnt <= 1e6, path, ": element '", el.name, "' ", i,
                  ": invalid list length ", cnt);
          const size_t m = static_cast<size_t>(cnt);
          if (!body.ascii() && m * SizeOf(p.type) > body.remaining())
            throw Error(
                Msg(path, ": truncated file in element '", el.name, "' ", i));
          std::vector<int> idx(m);
          for (size_t j = 0; j < m; ++j) {
            const double v = body.Read(p.type, "list entry");
            if (static_cast<int>(k) == face_list)
              Require(v >= 0 && v < static_cast<double>(c.xyz.size()), path,
                      ": face ", i, " refers to vertex ", v, " but there are ",
                      c.xyz.size(), " vertices");
            // Entries of other lists are skipped; only in-range values are
            // converted (a huge or NaN value must not reach the int cast).
            idx[j] = v >= 0 && v < 2e9 ? static_cast<int>(v) : -1;
          }
          if (static_cast<int>(k) == face_list && want_faces) {
            Require(m >= 3, path, ": face ", i, " has only ", m, " vertices");
            for (size_t j = 1; j + 1 < m; ++j)
              mesh.faces.emplace_back(idx[0], idx[j], idx[j + 1]);
          }
          continue;
        }
        const double v = body.Read(p.type, p.name.c_str());
        if (!is_vertex || field[k] < 0) continue;
        const int f = field[k];
        if (f < 3) {
          c.xyz[i][f] = static_cast<float>(v);
        } else if (f < 6) {
          if (c.has_normal()) c.normal[i][f - 3] = static_cast<float>(v);
        } else if (f < 9) {
          if (c.has_rgb())
            c.rgb[i][f - 6] = static_cast<float>(v * ColourScale(p.type));
        } else if (f == 9) {
          c.confidence[i] = static_cast<float>(v);
        } else {
          c.support[i] = static_cast<uint16_t>(std::clamp(v, 0.0, 65535.0));
        }
      }
      if (is_vertex)
        Require(c.xyz[i].allFinite(), path, ": vertex ", i,
                " has a non-finite position");
    }
  }
  Require(have_vertex, path, ": PLY file has no vertex element");
  return mesh;
}

}  // namespace

void WritePly(const std::string& path, const PointCloud& cloud) {
  Write(path, cloud, nullptr);
}

void WritePly(const std::string& path, const Mesh& mesh) {
  Write(path, mesh.vertices, &mesh.faces);
}

void WritePlyChunked(const std::string& path, size_t n,
                     const PointChunkSource& chunk, size_t chunk_points) {
  Require(chunk_points > 0, path, ": chunk_points must be > 0");
  auto get = [&](size_t begin) {
    const size_t end = std::min(n, begin + chunk_points);
    PointCloud c = chunk(begin, end);
    CheckCloud(path, c);
    Require(c.size() == end - begin, path, ": the chunk source gave ", c.size(),
            " points for [", begin, ", ", end, ")");
    return c;
  };
  PointCloud first = get(0);
  const std::string header = Header(n, first, nullptr);
  auto same_layout = [&](const PointCloud& c) {
    return c.has_normal() == first.has_normal() &&
           c.has_rgb() == first.has_rgb() &&
           c.has_confidence() == first.has_confidence() &&
           c.has_support() == first.has_support();
  };
  WriteFileAtomically(path, [&](std::ostream& os) {
    os.write(header.data(), static_cast<std::streamsize>(header.size()));
    std::string buf;
    buf.reserve(kFlushBytes + 64);
    PutVertices(first, &buf, os);
    for (size_t begin = first.size(); begin < n; begin += chunk_points) {
      const PointCloud c = get(begin);
      Require(same_layout(c), path, ": the chunk at point ", begin,
              " has other attributes than the first");
      PutVertices(c, &buf, os);
    }
    os.write(buf.data(), static_cast<std::streamsize>(buf.size()));
  });
}

PointCloud ReadPlyCloud(const std::string& path) {
  return Read(path, false).vertices;
}

Mesh ReadPlyMesh(const std::string& path) { return Read(path, true); }

}  // namespace wild_mvs
