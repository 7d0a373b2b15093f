#pragma once
// A run killed at any moment, by SIGKILL or a job scheduler's timeout, leaves
// no temporary file behind. AtomicOutput and the output sets write to
// temporary files beside their targets; a signal that can be caught could
// remove them, but SIGKILL cannot be. So a program starts a guard: a small
// process forked at the start of main(), before any thread exists, which holds
// the read end of a pipe. The program tells it each temporary file (and each
// output directory) it creates and each it has renamed or removed. When the
// pipe closes, the program has ended: whatever is still listed was left by a
// run that died, and the guard removes it, then exits.
//
// The guard ignores the terminal's and the scheduler's polite signals (INT,
// TERM, HUP, QUIT) so that it outlives a program they stop; a SIGKILL sent to
// the whole process group stops it too, and then the next run of the same
// output removes what was left (AtomicOutput.h).
#include <string>

namespace dynsub {

// Starts the guard; call once, first thing in main(). Without it (unit tests,
// library users) the temporary files are still removed on every exit that
// unwinds, and by the next run after a kill.
void startTemporaryFileGuard();

namespace temporaryfiles {
// What the outputs tell the guard (no-ops when it is not running).
void created(const std::string& path);
void finished(const std::string& path);
void createdDirectory(const std::string& path);
void finishedDirectory(const std::string& path);

// The guard's channel (-1 without a guard). A library of DynSub's own that
// carries its own copy of this module (OwnLibrary.h) is handed the program's
// channel, so that its temporary files are told to the same guard.
int channel();
void useChannel(int channel);
}  // namespace temporaryfiles

}  // namespace dynsub
