#include "dynsub/TemporaryFileGuard.h"

#include <fcntl.h>
#include <signal.h>
#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <set>
#include <string>

namespace dynsub {

namespace {

int toGuard = -1;  // the pipe's write end, -1 without a guard

// One record: a kind ('+' a file made, '-' a file gone, 'D' a directory made,
// 'd' a directory gone), the path, and a NUL (paths may hold newlines).
void tell(char kind, const std::string& path) {
  if (toGuard < 0) return;
  const std::string record = kind + path + '\0';
  const char* data = record.data();
  std::size_t left = record.size();
  while (left > 0) {
    const ssize_t written = ::write(toGuard, data, left);
    if (written < 0) {
      if (errno == EINTR) continue;
      toGuard = -1;  // the guard is gone: nothing to tell any more
      return;
    }
    data += written;
    left -= static_cast<std::size_t>(written);
  }
}

[[noreturn]] void guard(int fromProgram) {
  for (int s : {SIGINT, SIGTERM, SIGHUP, SIGQUIT}) ::signal(s, SIG_IGN);
  // Holds no terminal or pipe of the program's caller open: a shell reading
  // the program's output sees its end when the program ends.
  for (int fd = 0; fd < 3; ++fd) {
    const int null = ::open("/dev/null", O_RDWR);
    if (null >= 0 && null != fd) {
      ::dup2(null, fd);
      ::close(null);
    }
  }
  for (int fd = 3; fd < 1024; ++fd)
    if (fd != fromProgram) ::close(fd);
  std::set<std::string> files, directories;
  std::string record;
  char buffer[4096];
  ssize_t got = 0;
  while ((got = ::read(fromProgram, buffer, sizeof buffer)) != 0) {
    if (got < 0) {
      if (errno == EINTR) continue;
      break;
    }
    for (ssize_t i = 0; i < got; ++i) {
      if (buffer[i] != '\0') {
        record += buffer[i];
        continue;
      }
      if (record.size() > 1) {
        const std::string path = record.substr(1);
        switch (record[0]) {
          case '+': files.insert(path); break;
          case '-': files.erase(path); break;
          case 'D': directories.insert(path); break;
          case 'd': directories.erase(path); break;
          default: break;
        }
      }
      record.clear();
    }
  }
  // The program has ended; what it left listed, it left by dying.
  for (const std::string& file : files) ::unlink(file.c_str());
  for (auto d = directories.rbegin(); d != directories.rend(); ++d) ::rmdir(d->c_str());  // only if empty
  ::_exit(0);
}

}  // namespace

void startTemporaryFileGuard() {
  if (toGuard >= 0) return;
  int ends[2];
  if (::pipe2(ends, O_CLOEXEC) != 0) return;  // no guard: the next run cleans up instead
  const pid_t pid = ::fork();
  if (pid < 0) {
    ::close(ends[0]);
    ::close(ends[1]);
    return;
  }
  if (pid == 0) {
    ::close(ends[1]);
    guard(ends[0]);
  }
  ::close(ends[0]);
  toGuard = ends[1];
  // A guard that is gone must not kill the program through SIGPIPE.
  ::signal(SIGPIPE, SIG_IGN);
}

namespace temporaryfiles {
void created(const std::string& path) { tell('+', path); }
void finished(const std::string& path) { tell('-', path); }
void createdDirectory(const std::string& path) { tell('D', path); }
void finishedDirectory(const std::string& path) { tell('d', path); }
int channel() { return toGuard; }
void useChannel(int channel) { toGuard = channel; }
}  // namespace temporaryfiles

}  // namespace dynsub
