#include "dynsub/AtomicOutput.h"

#include <fcntl.h>
#include <signal.h>
#include <sys/statvfs.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <csignal>
#include <cstring>
#include <filesystem>
#include <mutex>
#include <string>
#include <system_error>
#include <thread>
#include <vector>

#include "dynsub/Error.h"

namespace fs = std::filesystem;

namespace dynsub {

namespace {

std::string temporaryPrefix(long pid) { return ".tmp-" + std::to_string(pid) + "-"; }

// The temporaries in progress. Never destroyed: the interrupt's thread may
// use it while the process exits.
struct Temporaries {
  std::mutex mutex;
  std::vector<std::string> paths;
};

Temporaries& temporaries() {
  static Temporaries* const all = new Temporaries;
  return *all;
}

constexpr int kInterruptSignals[] = {SIGINT, SIGTERM, SIGHUP};

sigset_t interruptSignals() {
  sigset_t signals;
  sigemptyset(&signals);
  for (const int signal : kInterruptSignals) sigaddset(&signals, signal);
  return signals;
}

// The interrupt's pipe: the handler writes the signal's number, the cleanup
// thread reads it.
int interruptPipe[2] = {-1, -1};
pid_t interruptOwner = 0;

void forwardInterrupt(int signal) {
  // Not in a forked child before its exec, which is not the pipe's owner.
  if (getpid() == interruptOwner) {
    const int savedErrno = errno;
    const unsigned char number = static_cast<unsigned char>(signal);
    const bool passed = write(interruptPipe[1], &number, 1) == 1;
    errno = savedErrno;
    if (passed) return;
  }
  // End by the signal without the cleanup (delivered when this returns).
  std::signal(signal, SIG_DFL);
  raise(signal);
}

}  // namespace

void trackTemporary(const std::string& path) {
  Temporaries& all = temporaries();
  const std::lock_guard<std::mutex> lock(all.mutex);
  all.paths.push_back(path);
}

void untrackTemporary(const std::string& path) {
  Temporaries& all = temporaries();
  const std::lock_guard<std::mutex> lock(all.mutex);
  const auto last = std::find(all.paths.rbegin(), all.paths.rend(), path);
  if (last != all.paths.rend()) all.paths.erase(std::next(last).base());
}

void removeTemporariesOnInterrupt() {
  static std::once_flag once;
  std::call_once(once, [] {
    // Without a pipe (no file descriptor left) an interrupt ends the process
    // as usual, and the next run of the same outputs sweeps what it left.
    if (pipe2(interruptPipe, O_CLOEXEC) != 0) return;
    interruptOwner = getpid();
    // Threads started from here on block the signals, so that their system
    // calls are not interrupted; the cleanup thread below takes them. A thread
    // that a library started before this (a BLAS thread pool) does not block
    // them, and the handler there forwards the signal all the same.
    const sigset_t signals = interruptSignals();
    pthread_sigmask(SIG_BLOCK, &signals, nullptr);
    struct sigaction action = {};
    action.sa_handler = forwardInterrupt;
    action.sa_mask = signals;
    action.sa_flags = SA_RESTART;
    for (const int signal : kInterruptSignals) sigaction(signal, &action, nullptr);
    std::thread([signals] {
      pthread_sigmask(SIG_UNBLOCK, &signals, nullptr);
      unsigned char received = 0;
      ssize_t count = 0;
      while ((count = read(interruptPipe[0], &received, 1)) < 0 && errno == EINTR) {
      }
      if (count != 1) return;
      Temporaries& all = temporaries();
      // Held to the end: an output begun after this is not begun at all.
      all.mutex.lock();
      std::error_code ignored;
      for (auto path = all.paths.rbegin(); path != all.paths.rend(); ++path) fs::remove_all(*path, ignored);
      // End as the signal would have ended the process without this. This
      // thread does not block it, so raise() delivers it here.
      std::signal(received, SIG_DFL);
      raise(received);
    }).detach();
  });
}

std::string temporaryName(const std::string& name) { return temporaryPrefix(::getpid()) + name; }

void removeStaleTemporaries(const fs::path& directory, const std::string& name) {
  std::error_code error;
  for (fs::directory_iterator entry(directory.empty() ? "." : directory, error), end; !error && entry != end;
       entry.increment(error)) {
    const std::string file = entry->path().filename().string();
    if (file.size() <= name.size() + 6 || file.compare(0, 5, ".tmp-") != 0 ||
        file.compare(file.size() - name.size() - 1, name.size() + 1, "-" + name) != 0)
      continue;
    const std::string digits = file.substr(5, file.size() - name.size() - 6);
    if (digits.empty() || digits.size() > 9 ||
        !std::all_of(digits.begin(), digits.end(), [](unsigned char c) { return std::isdigit(c); }))
      continue;
    const long pid = std::stol(digits);
    if (pid == ::getpid() || ::kill(static_cast<pid_t>(pid), 0) == 0 || errno != ESRCH) continue;
    std::error_code ignored;
    fs::remove_all(entry->path(), ignored);  // a file, or an output set's folder (OutputSet.h)
  }
}

AtomicOutput::AtomicOutput(std::string target) : target_(std::move(target)) {
  requireWritableDirectoryFor(target_);
  const fs::path path(target_);
  const std::string name = path.filename().string();
  const std::string prefix = temporaryPrefix(::getpid());
  if (name.compare(0, prefix.size(), prefix) == 0) {
    // The target is already this process's temporary file (a writer handed the
    // path of an enclosing output set): it is written in place, and the
    // enclosing output makes it appear.
    temporary_ = target_;
    return;
  }
  removeStaleTemporaries(path.parent_path(), name);
  // The process id keeps two concurrent runs from sharing a temporary file; the
  // name ends with the target's file name, so writers still see its extension.
  temporary_ = (path.parent_path() / (prefix + name)).string();
  trackTemporary(temporary_);
}

AtomicOutput::~AtomicOutput() {
  if (temporary_ == target_) return;
  if (!committed_) {
    std::error_code ignored;
    fs::remove(temporary_, ignored);
  }
  untrackTemporary(temporary_);
}

void AtomicOutput::commit() {
  std::error_code error;
  if (!fs::exists(temporary_, error)) {
    throw Error(target_, "the writer produced no output");
  }
  if (temporary_ != target_) fs::rename(temporary_, target_, error);
  if (error) {
    throw Error(target_, "cannot move the finished output into place: " + error.message());
  }
  committed_ = true;
}

std::string withoutTemporaryPrefix(const std::string& text) {
  const std::string prefix = temporaryPrefix(::getpid());
  std::string result = text;
  for (std::size_t at = result.find(prefix); at != std::string::npos; at = result.find(prefix, at))
    result.erase(at, prefix.size());
  return result;
}

Error writeFailure(const std::string& path, const std::string& detail) {
  const int saved = errno;
  std::string reason;
  // A full file system is named as such whatever the writer reported (a
  // pseudo file system, /proc say, has no blocks at all, and is not full).
  fs::path directory = fs::path(path).parent_path();
  if (directory.empty()) directory = ".";
  struct statvfs space {};
  if (::statvfs(directory.c_str(), &space) == 0 && space.f_blocks > 0 && space.f_bavail == 0)
    reason = std::strerror(ENOSPC);
  else if (!detail.empty())
    reason = detail;
  else
    reason = saved ? std::strerror(saved) : "the stream failed";
  return Error(withoutTemporaryPrefix(path), "could not be written: " + reason);
}

void requireWritableDirectoryFor(const std::string& path) {
  fs::path directory = fs::path(path).parent_path();
  if (directory.empty()) directory = ".";
  std::error_code error;
  if (!fs::is_directory(directory, error)) {
    if (fs::exists(directory, error))
      throw Error(path, "'" + directory.string() + "' is a file, not a directory to write into");
    throw Error(path, "the output directory '" + directory.string() + "' does not exist");
  }
  if (::access(directory.c_str(), W_OK) != 0) {
    throw Error(path, "the output directory '" + directory.string() + "' is not writable");
  }
  // Found here, before a run, rather than when its finished file cannot be
  // moved into place.
  if (fs::is_directory(path, error)) throw Error(path, "is a directory; give the name of a file to write");
}

}  // namespace dynsub
