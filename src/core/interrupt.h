// Interrupting a run (Ctrl-C, or SIGTERM from a batch system): the first signal asks the run to
// stop at the next iteration the solvers check; the model then writes its current (dp: least
// residual) state, the output directory is committed, and the command line exits with 128 + the
// signal number. A second signal ends the process at once, as without the handler.
//
// The steps before a run has anything to write (Gmsh's meshing, which cannot poll; the setup; dp's
// solver until its first iteration is complete; ngf's until its first increment) run inside a
// BeforeResults scope, where the first signal ends the process at once: nothing has been computed
// that is worth writing, and the output directory is left as it was.
#pragma once

#include <string>

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

  /// While an object of this class lives, a handled signal ends the process at once with exit
  /// status 128 + the signal, saying that nothing was computed and then `outcome` (what became of
  /// the output directory: the run's target is left as it was, and its staging directory keeps
  /// this run's log until the next run into it). For the steps before a run has anything to
  /// write, which do not poll requested(): a mesh of a million triangles takes Gmsh minutes. A
  /// signal that arrived before the scope began ends the process when it begins. Scopes do not
  /// nest.
  class BeforeResults
  {
  public:
    explicit BeforeResults(const std::string &outcome);
    ~BeforeResults();
    BeforeResults(const BeforeResults &) = delete;
    BeforeResults &
    operator=(const BeforeResults &) = delete;
  };
} // namespace granflow::interrupt
