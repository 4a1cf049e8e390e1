// Interrupting a run (Ctrl-C, or SIGTERM from a batch system): the first signal asks the run to
// stop at the next iteration the solvers check; the model then writes its current (dp: least
// residual) state, the output directory is committed, and the command line exits with 128 + the
// signal number. A second signal ends the process at once, as without the handler.
#pragma once

namespace granflow::interrupt
{
  /// Handles SIGINT and SIGTERM as above (the command line calls it before a run).
  void
  install();

  /// True once a handled signal has arrived (async-signal-safe flag; cheap enough to poll in
  /// inner loops).
  bool
  requested();

  /// The signal that arrived (SIGINT, SIGTERM), 0 if none.
  int
  signal_number();

  /// "SIGINT", "SIGTERM" or "a signal".
  const char *
  signal_name();
} // namespace granflow::interrupt
