// Output files are never half-written: every file mfr writes (images, JSON, CSV, reports, models,
// datasets) goes through writeFileAtomically, which writes a temporary file in the destination's
// folder, flushes it to disk and renames it into place. An interrupted or failed write leaves the
// previous file (or none), never a truncated one that looks valid.
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <string_view>

#include "mfr/core/result.hpp"

namespace mfr {

/// Writes `bytes` to `path` atomically (its folder made if missing): the data goes to a temporary
/// file in the same folder (an unnamed O_TMPFILE where the file system has them, so a killed
/// process leaves nothing behind; otherwise ".NAME.tmp.PID.N.T", removed on failure; NAME cut to
/// 128 bytes, so that any name the file system takes, up to NAME_MAX, can be written), is fsync'ed,
/// and replaces `path` by rename (an existing file's permissions are kept). A special file (a
/// terminal, /dev/stdout, a pipe) has nothing to replace and is written directly. Errors ("PATH:
/// cannot open for writing (...)", "PATH: write error (...)") name `path`; on error `path` is
/// untouched.
Result<void> writeFileAtomically(const std::string& path, std::string_view bytes);

/// fsync of a folder, so that renames in it are durable; best effort (errors are ignored).
void syncFolder(const std::string& dir);

/// Test hook (tests only): called after every chunk written to the temporary file with the
/// destination path and the bytes written so far; returning true makes that write fail there as an
/// I/O error would. Not thread-safe: set it while no file is being written. Empty: no injection.
using WriteFailureInjection = std::function<bool(const std::string& path, uint64_t written)>;
void setWriteFailureInjectionForTests(WriteFailureInjection hook);

}  // namespace mfr
