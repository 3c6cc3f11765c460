// Copyright wild_mvs authors.
#include "wild_mvs/io/pfm.h"

#include <cctype>
#include <cmath>
#include <cstring>

#include "text_util.h"
#include "wild_mvs/core/error.h"
#include "wild_mvs/io/atomic_file.h"

namespace wild_mvs {
namespace {

// Reads the next whitespace-separated header token starting at *pos.
std::string HeaderToken(const std::string& d, size_t* pos,
                        const std::string& path, const char* what) {
  while (*pos < d.size() && std::isspace(static_cast<unsigned char>(d[*pos])))
    ++*pos;
  const size_t b = *pos;
  while (*pos < d.size() && !std::isspace(static_cast<unsigned char>(d[*pos])))
    ++*pos;
  Require(*pos > b && *pos - b < 64, path, ": truncated or bad PFM header (",
          what, ")");
  return d.substr(b, *pos - b);
}

}  // namespace

cv::Mat ReadPfm(const std::string& path) {
  const std::string d = io_detail::ReadWholeFile(path);
  size_t pos = 0;
  const std::string magic = HeaderToken(d, &pos, path, "magic");
  Require(magic == "Pf" || magic == "PF", path, ": not a PFM file (magic '",
          magic.substr(0, 8), "', expected Pf or PF)");
  const int channels = magic == "PF" ? 3 : 1;
  const std::string where = path + ": PFM header";
  const long long w =
      io_detail::ParseInt(HeaderToken(d, &pos, path, "width"), where, "width");
  const long long h = io_detail::ParseInt(HeaderToken(d, &pos, path, "height"),
                                          where, "height");
  const double scale = io_detail::ParseDouble(
      HeaderToken(d, &pos, path, "scale"), where, "scale");
  Require(w > 0 && h > 0 && w <= 1000000 && h <= 1000000, path,
          ": invalid PFM size ", w, "x", h);
  Require(scale != 0, path, ": PFM scale must be non-zero");
  Require(pos < d.size(), path, ": truncated PFM (no data)");
  ++pos;  // the single whitespace byte after the scale
  const size_t need = static_cast<size_t>(w) * static_cast<size_t>(h) *
                      channels * sizeof(float);
  Require(d.size() - pos >= need, path, ": truncated PFM: ", w, "x", h, "x",
          channels, " floats need ", need, " bytes, file has ", d.size() - pos);
  cv::Mat img(static_cast<int>(h), static_cast<int>(w),
              channels == 3 ? CV_32FC3 : CV_32F);
  const bool little = scale < 0;
  const size_t row_bytes = static_cast<size_t>(w) * channels * sizeof(float);
  for (int r = 0; r < img.rows; ++r) {
    const char* src = d.data() + pos + row_bytes * (img.rows - 1 - r);
    unsigned char* dst = img.ptr<unsigned char>(r);
    std::memcpy(dst, src, row_bytes);
    if (!little) {
      for (size_t i = 0; i < row_bytes; i += 4) {
        std::swap(dst[i], dst[i + 3]);
        std::swap(dst[i + 1], dst[i + 2]);
      }
    }
  }
  return img;
}

void WritePfm(const std::string& path, const cv::Mat& image) {
  Require(!image.empty(), path, ": cannot write an empty image as PFM");
  Require(image.channels() == 1 || image.channels() == 3, path,
          ": PFM needs 1 or 3 channels, image has ", image.channels());
  cv::Mat f;
  if (image.depth() == CV_32F)
    f = image;
  else
    image.convertTo(f, CV_MAKETYPE(CV_32F, image.channels()));
  WriteFileAtomically(path, [&](std::ostream& os) {
    os << (f.channels() == 3 ? "PF" : "Pf") << "\n"
       << f.cols << " " << f.rows << "\n-1\n";
    const size_t row_bytes = static_cast<size_t>(f.cols) * f.elemSize();
    for (int r = f.rows - 1; r >= 0; --r)
      os.write(reinterpret_cast<const char*>(f.ptr(r)),
               static_cast<std::streamsize>(row_bytes));
  });
}

}  // namespace wild_mvs
