// Copyright wild_mvs authors.
#include "wild_mvs/io/atomic_file.h"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <random>

#include "wild_mvs/core/error.h"

namespace wild_mvs {
namespace {

namespace fs = std::filesystem;

std::string TempNameFor(const std::string& path) {
  static thread_local std::mt19937_64 rng{std::random_device{}()};
  const fs::path p(path);
  const std::string ext = p.extension().string();  // keep for cv::imwrite
  // The process id keeps concurrent processes writing the same file (e.g.
  // --shard runs and their run.yaml) apart; the random part, the threads.
  return (p.parent_path() /
          ("." + p.stem().string() + ".tmp" + std::to_string(::getpid()) + "_" +
           std::to_string(rng() % 1000000) + ext))
      .string();
}

void PrepareParent(const std::string& path) {
  const fs::path parent = fs::path(path).parent_path();
  if (parent.empty()) return;
  std::error_code ec;
  fs::create_directories(parent, ec);
  Require(!ec, path, ": cannot create folder '", parent.string(),
          "': ", ec.message());
}

// fsync the file and move it into place; removes tmp on failure.
void Commit(const std::string& tmp, const std::string& path) {
  const int fd = ::open(tmp.c_str(), O_RDONLY);
  if (fd >= 0) {
    const bool ok = ::fsync(fd) == 0;
    const int err = errno;
    ::close(fd);
    if (!ok) {
      std::remove(tmp.c_str());
      throw Error(Msg(path, ": cannot write: ", std::strerror(err)));
    }
  }
  if (std::rename(tmp.c_str(), path.c_str()) != 0) {
    const int err = errno;
    std::remove(tmp.c_str());
    throw Error(Msg(path, ": cannot move the finished file into place: ",
                    std::strerror(err)));
  }
}

}  // namespace

void WriteFileAtomically(const std::string& path,
                         const std::function<void(std::ostream&)>& write) {
  PrepareParent(path);
  const std::string tmp = TempNameFor(path);
  {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    if (!out) {
      const int err = errno;
      throw Error(Msg(path, ": cannot open for writing: ", std::strerror(err)));
    }
    errno = 0;  // so a failure below reports its own cause, not a stale one
    try {
      write(out);
    } catch (...) {
      out.close();
      std::remove(tmp.c_str());
      throw;
    }
    out.flush();
    const int err = errno;
    if (!out) {
      out.close();
      std::remove(tmp.c_str());
      throw Error(Msg(
          path, ": write failed: ", err ? std::strerror(err) : "stream error"));
    }
    out.close();
    if (out.fail()) {
      std::remove(tmp.c_str());
      throw Error(Msg(path, ": write failed on close"));
    }
  }
  Commit(tmp, path);
}

void ProduceFileAtomically(
    const std::string& path,
    const std::function<bool(const std::string&)>& produce) {
  PrepareParent(path);
  const std::string tmp = TempNameFor(path);
  bool ok = false;
  errno = 0;  // a producer that fails without errno must not show a stale one
  try {
    ok = produce(tmp);
  } catch (...) {
    std::remove(tmp.c_str());
    throw;
  }
  if (!ok) {
    const int err = errno;
    std::remove(tmp.c_str());
    throw Error(Msg(path, ": cannot write",
                    err ? std::string(": ") + std::strerror(err) : ""));
  }
  Commit(tmp, path);
}

}  // namespace wild_mvs
