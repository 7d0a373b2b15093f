#pragma once
// Writes an output file so that it either appears complete or not at all: the
// content goes to a temporary file beside the target, which is renamed onto the
// target by commit(). If commit() is never called (an exception, a failed
// check), the destructor removes the temporary file and the target is untouched.
//
// The temporary file is ".tmp-<pid>-<name>". A program that called
// removeTemporariesOnInterrupt() removes its temporaries when interrupted
// (Ctrl-C, SIGTERM, SIGHUP). A run killed by a signal that cannot be caught
// (SIGKILL, a scheduler's hard limit) leaves them behind; the next output of
// the same name removes those whose process is gone (the sweep), so a rerun
// of the job cleans up after the killed one.
// A target that is already this process's temporary file (a writer given the
// path of an enclosing output) is written in place: the enclosing output
// removes it or makes it appear.
#include <filesystem>
#include <string>

#include "dynsub/Error.h"

namespace dynsub {

class AtomicOutput {
 public:
  explicit AtomicOutput(std::string target);
  ~AtomicOutput();
  AtomicOutput(const AtomicOutput&) = delete;
  AtomicOutput& operator=(const AtomicOutput&) = delete;

  // Where to write the content; same directory and extension as the target so
  // that writers choosing a format by extension still work.
  const std::string& temporaryPath() const { return temporary_; }
  const std::string& target() const { return target_; }
  // Renames the temporary file onto the target; throws dynsub::Error naming the
  // target if the temporary file is missing or the rename fails.
  void commit();

 private:
  std::string target_;
  std::string temporary_;
  bool committed_ = false;
};

// Makes SIGINT, SIGTERM and SIGHUP remove this process's outputs in progress
// (AtomicOutput's temporary files, OutputSet's folders) before the process
// ends by the signal as it would have without this. Call it first in main.
// A handler passes the signal through a pipe to one thread of its own, which
// may do what a signal handler may not (remove a folder). Threads started
// after the call block the signals, so that only that thread or a thread a
// library started earlier takes them. A child process inherits the blocked
// signals: a program that starts one unblocks them in it (Figures.cpp,
// FigureDisplay.cpp).
void removeTemporariesOnInterrupt();

// Temporaries that an interrupt removes (removeTemporariesOnInterrupt): a
// file or folder from when it is made to when it is moved into place or
// removed. AtomicOutput and OutputSet keep theirs here.
void trackTemporary(const std::string& path);
void untrackTemporary(const std::string& path);

// This process's temporary name for `name`: ".tmp-<pid>-<name>".
std::string temporaryName(const std::string& name);

// Removes what killed runs left for `name` in `directory`: the files or
// folders ".tmp-<pid>-<name>" whose process no longer exists. A live
// process's are kept (a concurrent run's, or an unrelated process that took
// over the pid).
void removeStaleTemporaries(const std::filesystem::path& directory, const std::string& name);

// Throws dynsub::Error naming `path` unless its directory exists and is writable.
void requireWritableDirectoryFor(const std::string& path);

// `text` with this process's temporary-file prefix taken out of the file
// names in it, so that a message names the file the user asked for.
std::string withoutTemporaryPrefix(const std::string& text);

// The error for a file whose writing failed (call right after the failure):
// names the target and the reason: "No space left on device" when its file
// system is full, else `detail` (a library's own report) or the system's
// (errno, e.g. "File too large").
Error writeFailure(const std::string& path, const std::string& detail = "");

}  // namespace dynsub
