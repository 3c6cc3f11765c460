// Copyright wild_mvs authors. Atomic output files.
//
// Every output file is written to a temporary name in the same folder and
// renamed over the destination only when complete and flushed, so a crash,
// a full disk or a kill never leaves a half-written file and never damages
// an earlier result.
#pragma once

#include <functional>
#include <ostream>
#include <string>

namespace wild_mvs {

// Calls write(stream) on a temporary file beside `path`, checks the stream,
// flushes and fsyncs, then renames it to `path`. On any failure the temporary
// file is removed, `path` is untouched, and Error is thrown naming `path` and
// the problem (e.g. "No space left on device"). Creates missing parent
// folders.
void WriteFileAtomically(const std::string& path,
                         const std::function<void(std::ostream&)>& write);

// Same for content produced by a function that writes a complete file at a
// given path itself (e.g. cv::imwrite): produce(tmp_path) must return true
// on success.
void ProduceFileAtomically(
    const std::string& path,
    const std::function<bool(const std::string&)>& produce);

}  // namespace wild_mvs
