// SIGINT and SIGTERM end a run cleanly (docs/reliability.md, "Signals"): the handler only
// sets a flag, long loops check it between steps (throwIfInterrupted) and the atomic writer
// stops its write, so unwinding removes the temporary, keeps every file that was complete and
// `fvp` exits 128 + the signal (130, 143). A second signal does not wait for the next check:
// the handler removes the temporaries being written (registered here) and exits at once.
#pragma once

#include <stdexcept>
#include <string>

namespace fvp::host {

/// Thrown by throwIfInterrupted (and the atomic writer) once a signal asked the run to stop.
class Interrupted : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// Installs the SIGINT and SIGTERM handlers (the fvp program does, once, at start).
void installInterruptHandlers();

/// The signal that asked the run to stop, or 0.
int interruptSignal();

/// Throws Interrupted ("interrupted by SIGTERM") once a signal asked the run to stop.
void throwIfInterrupted();

/// A temporary file the second signal's handler removes before exiting, for as long as an
/// object lives (the atomic writer holds one per temporary). Paths longer than PATH_MAX and
/// temporaries beyond a fixed number of slots are not registered (the first signal's clean
/// stop still removes them).
class RegisteredTemporary {
 public:
  explicit RegisteredTemporary(const std::string& path);
  ~RegisteredTemporary();
  RegisteredTemporary(const RegisteredTemporary&) = delete;
  RegisteredTemporary& operator=(const RegisteredTemporary&) = delete;

 private:
  int slot_ = -1;
};

}  // namespace fvp::host
