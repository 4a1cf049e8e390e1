// Run log: everything goes to <output>/log.txt; the console gets the same lines unless quiet.
// Progress lines (for runs longer than a few seconds) go to the console only, at most every
// `progress_interval` seconds.
#pragma once

#include <chrono>
#include <fstream>
#include <ostream>
#include <sstream>
#include <string>

namespace granflow
{
  class Logger
  {
  public:
    Logger(const std::string &log_file, bool echo_to_console);

    /// Writes a line (or block ending in '\n') to the log file and, if echoing, to stdout.
    void
    print(const std::string &text);

    /// The log file itself, for solver iteration tables (written as they happen, so a long or
    /// interrupted run shows how far it got).
    std::ostream &
    table()
    {
      return file;
    }
    void
    flush_table();

    /// Console-only progress, throttled.
    void
    progress(const std::string &text);

    /// Console-only: the start of a step that may be long (a factorisation), so that a run is
    /// never silent for long; shown once the run has taken a second, not for quick runs.
    void
    phase(const std::string &text);

    double
    elapsed() const;

  private:
    /// "  [12 s] text" on the console (if echoed); restarts the progress interval.
    void
    stamp(const std::string &text);

    std::ofstream                         file;
    bool                                  echo;
    std::chrono::steady_clock::time_point start, last_progress;
    double                                progress_interval = 2.;
  };
} // namespace granflow
