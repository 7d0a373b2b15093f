// The X display figures are rendered on (Figures.h: displayAvailable,
// figureDisplay, prepareFigureDisplay). A file of its own: the X11 and GLX
// headers' macros (None, AllValues) break VTK's headers.
#include "dynsub/Figures.h"

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <sys/prctl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <future>
#include <optional>
#include <string>

#include <GL/glx.h>
#include <X11/Xlib.h>

namespace dynsub {

bool displayAvailable(std::string* why) {
  const char* name = std::getenv("DISPLAY");
  if (!name || !*name) {
    if (why) *why = "DISPLAY is not set (run under xvfb-run on a machine without a screen)";
    return false;
  }
  Display* display = XOpenDisplay(nullptr);
  if (!display) {
    if (why) *why = std::string("cannot open the X display ") + name;
    return false;
  }
  XCloseDisplay(display);
  return true;
}

namespace {

// The virtual X server figureDisplay() starts: stopped when the process
// exits (the static's destructor), and by the kernel when the process dies
// (PR_SET_PDEATHSIG), so no server outlives its run.
struct PrivateXServer {
  pid_t pid = -1;
  ~PrivateXServer() {
    if (pid <= 0) return;
    kill(pid, SIGTERM);
    waitpid(pid, nullptr, 0);
  }
};

PrivateXServer& privateXServer() {
  static PrivateXServer server;
  return server;
}

// Xvfb started on a free display number: it writes the number to the pipe
// given by -displayfd once it accepts connections.
struct LaunchedServer {
  pid_t pid = -1;
  int numberPipe = -1;  // the read end
};

// Forks and starts Xvfb; false, with `why`, when no pipe could be made.
// On the thread that will outlive the server's use (the main thread):
// PR_SET_PDEATHSIG signals the child when the thread that forked it ends,
// not the process.
bool launchPrivateXServer(LaunchedServer& server, std::string* why) {
  int fds[2];
  if (pipe(fds) != 0) {
    if (why) *why = "DISPLAY is not set, and no pipe could be made to start Xvfb";
    return false;
  }
  const std::string writeEnd = std::to_string(fds[1]);
  const pid_t parent = getpid();
  const pid_t pid = fork();
  if (pid == 0) {  // only async-signal-safe calls until exec
    // Signals this process blocks (AtomicOutput.h's interrupt) are not
    // blocked in Xvfb: the SIGTERM below must end it.
    sigset_t none;
    sigemptyset(&none);
    sigprocmask(SIG_SETMASK, &none, nullptr);
    prctl(PR_SET_PDEATHSIG, SIGTERM);
    if (getppid() != parent) _exit(1);
    close(fds[0]);
    const int null = open("/dev/null", O_RDWR);
    dup2(null, 0);
    dup2(null, 1);
    dup2(null, 2);
    execlp("Xvfb", "Xvfb", "-displayfd", writeEnd.c_str(), "-screen", "0", "1280x1024x24", "-nolisten", "tcp",
           "-noreset", static_cast<char*>(nullptr));
    _exit(127);
  }
  close(fds[1]);
  server.pid = pid;
  server.numberPipe = fds[0];
  return true;
}

// Waits (up to 10 s) until the launched Xvfb accepts connections; `display`
// is then its name. Any thread may wait.
bool awaitPrivateXServer(const LaunchedServer& server, std::string& display, std::string* why) {
  std::string number;
  bool complete = false;
  if (server.pid > 0) {
    pollfd wait{server.numberPipe, POLLIN, 0};
    char c;
    while (!complete && poll(&wait, 1, 10000) > 0 && read(server.numberPipe, &c, 1) == 1) {
      if (c == '\n') complete = !number.empty();
      else number += c;
    }
  }
  close(server.numberPipe);
  if (!complete) {
    if (server.pid > 0) {
      kill(server.pid, SIGTERM);
      waitpid(server.pid, nullptr, 0);
    }
    if (why) *why = "DISPLAY is not set and no virtual X server could be started (install the xvfb package)";
    return false;
  }
  privateXServer().pid = server.pid;
  display = ":" + number;
  return true;
}

// A display made ready for figures: its name (set as DISPLAY when it was
// started here), whether it works, and why not.
struct PreparedDisplay {
  std::string name;
  bool started = false, ready = false;
  std::string why;
};

// `prepared` names the display, or `server` was launched for it.
PreparedDisplay prepareDisplay(PreparedDisplay prepared, const LaunchedServer& server) {
  if (prepared.started && !awaitPrivateXServer(server, prepared.name, &prepared.why)) {
    prepared.started = false;
    return prepared;
  }
  Display* display = XOpenDisplay(prepared.name.c_str());
  if (!display) {
    prepared.why = "cannot open the X display " + prepared.name;
    return prepared;
  }
  // Asking for a framebuffer configuration loads and starts the OpenGL driver.
  // The connection stays open: closing it would unload the driver again.
  const int attributes[] = {GLX_DRAWABLE_TYPE, GLX_WINDOW_BIT, GLX_RENDER_TYPE, GLX_RGBA_BIT, None};
  int count = 0;
  if (GLXFBConfig* configs = glXChooseFBConfig(display, DefaultScreen(display), attributes, &count)) XFree(configs);
  prepared.ready = true;
  return prepared;
}

std::future<PreparedDisplay>& displayPreparation() {
  static std::future<PreparedDisplay> preparation;
  return preparation;
}

// The display once figureDisplay() has waited for it: one per process.
std::optional<PreparedDisplay>& preparedDisplay() {
  static std::optional<PreparedDisplay> prepared;
  return prepared;
}

}  // namespace

void prepareFigureDisplay() {
  if (displayPreparation().valid() || preparedDisplay()) return;
  PreparedDisplay prepared;
  LaunchedServer server;
  const char* name = std::getenv("DISPLAY");
  if (name && *name) {
    prepared.name = name;
  } else if (launchPrivateXServer(server, &prepared.why)) {
    prepared.started = true;
  } else {
    displayPreparation() = std::async(std::launch::deferred, [prepared] { return prepared; });
    return;
  }
  displayPreparation() = std::async(std::launch::async, prepareDisplay, prepared, server);
}

bool figureDisplay(std::string* why) {
  // Made ready here when no one asked for it ahead.
  prepareFigureDisplay();
  if (displayPreparation().valid()) {
    preparedDisplay() = displayPreparation().get();
    if (preparedDisplay()->started) setenv("DISPLAY", preparedDisplay()->name.c_str(), 1);
  }
  if (!preparedDisplay()->ready && why) *why = preparedDisplay()->why;
  return preparedDisplay()->ready;
}

}  // namespace dynsub
