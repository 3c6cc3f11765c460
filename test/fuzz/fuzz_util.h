// Copyright wild_mvs authors. Helpers shared by the libFuzzer harnesses.
//
// The readers take file names, so a harness writes the fuzz input to files in
// a private scratch folder (in /dev/shm when it exists, to stay fast) and
// calls the reader on them. Readers of several files (COLMAP: cameras,
// images, points3D) get one input holding all of them, separated by the
// marker kSplit; a missing part means the file is absent.
//
// The contract checked: a reader either succeeds or throws wild_mvs::Error.
// Anything else (a crash, a sanitizer report, another exception type, a
// hang, a huge allocation) is a finding.
#pragma once

#include <sys/stat.h>
#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <string>
#include <vector>

namespace wild_mvs {
namespace fuzz {

// Separates the files of a multi-file input.
constexpr char kSplit[] = "#WMSPLIT";

// Splits `data` at every kSplit into at most `max_parts` parts (the last
// part keeps any further markers).
inline std::vector<std::string> SplitInput(const uint8_t* data, size_t size,
                                           size_t max_parts) {
  const std::string all(reinterpret_cast<const char*>(data), size);
  const std::string marker(kSplit);
  std::vector<std::string> parts;
  size_t start = 0;
  while (parts.size() + 1 < max_parts) {
    const size_t pos = all.find(marker, start);
    if (pos == std::string::npos) break;
    parts.push_back(all.substr(start, pos - start));
    start = pos + marker.size();
  }
  parts.push_back(all.substr(start));
  return parts;
}

// Names written into the scratch folder (removed at exit).
inline std::vector<std::string>& ScratchNames() {
  static auto* names = new std::vector<std::string>();  // never destroyed
  return *names;
}

// A scratch folder private to this process, created on first use under
// $WILD_MVS_FUZZ_TMP, else /dev/shm, else /tmp; removed at a normal exit.
inline const std::string& ScratchDir() {
  static const std::string& dir = *new std::string([] {
    const char* env = std::getenv("WILD_MVS_FUZZ_TMP");
    const char* base = env && *env                     ? env
                       : access("/dev/shm", W_OK) == 0 ? "/dev/shm"
                                                       : "/tmp";
    std::string tmpl = std::string(base) + "/wild_mvs_fuzz_XXXXXX";
    std::vector<char> buf(tmpl.begin(), tmpl.end());
    buf.push_back('\0');
    if (!mkdtemp(buf.data())) std::abort();
    std::atexit([] {
      for (const std::string& n : ScratchNames())
        std::remove((ScratchDir() + "/" + n).c_str());  // files, empty dirs
      rmdir(ScratchDir().c_str());
    });
    return std::string(buf.data());
  }());  // never destroyed: the exit handler still needs it
  return dir;
}

// Writes `content` to ScratchDir()/name and returns the path.
inline std::string WriteScratch(const std::string& name,
                                const std::string& content) {
  const std::string path = ScratchDir() + "/" + name;
  bool known = false;
  for (const std::string& n : ScratchNames()) known = known || n == name;
  if (!known) ScratchNames().push_back(name);
  FILE* f = std::fopen(path.c_str(), "wb");
  if (!f) std::abort();
  if (!content.empty() &&
      std::fwrite(content.data(), 1, content.size(), f) != content.size())
    std::abort();
  std::fclose(f);
  return path;
}

// Removes ScratchDir()/name if present.
inline void RemoveScratch(const std::string& name) {
  const std::string path = ScratchDir() + "/" + name;
  std::remove(path.c_str());
}

// Small images a.png, b.png, c.png (640x480, 320x240, 64x48) in the scratch
// folder and in its images/ subfolder, for readers that take image sizes
// from the files their cameras name (Bundler, Middlebury).
inline void WriteSampleImages() {
  const int sizes[3][2] = {{640, 480}, {320, 240}, {64, 48}};
  const char* names[3] = {"a.png", "b.png", "c.png"};
  mkdir((ScratchDir() + "/images").c_str(), 0755);
  for (int i = 0; i < 3; ++i) {
    const cv::Mat img(sizes[i][1], sizes[i][0], CV_8UC3,
                      cv::Scalar(40 * i, 100, 200));
    for (const std::string sub : {"", "images/"}) {
      if (!cv::imwrite(ScratchDir() + "/" + sub + names[i], img)) std::abort();
      ScratchNames().push_back(sub + names[i]);
    }
  }
  ScratchNames().push_back("images");  // removed last (after its files)
}

}  // namespace fuzz
}  // namespace wild_mvs
