// Error types that map to the exit status of the command line (README, "Exit status"):
// InputError -> 2 (bad case file, value out of range, missing or unusable mesh),
// ConvergenceError -> 3 (a solver did not converge; results written so far are kept),
// Interrupted -> 128 + the signal (the run was stopped by SIGINT / SIGTERM; results so far kept).
#pragma once

#include <stdexcept>
#include <string>

namespace granflow
{
  /// Bad input. The message names the file, the entry and what was expected, e.g.
  /// "cases/x.prm: entry 'Rheology/mu' = -1 is out of range: expected a number in [0, inf)".
  class InputError : public std::runtime_error
  {
  public:
    InputError(const std::string &file, const std::string &entry, const std::string &what);
    explicit InputError(const std::string &message);

    /// The entry ("Section/key") and the text after it, when the error names one; else empty.
    const std::string &
    entry() const
    {
      return entry_;
    }
    const std::string &
    detail() const
    {
      return detail_;
    }

  private:
    std::string entry_, detail_;
  };

  /// A solver stopped without reaching its tolerance.
  class ConvergenceError : public std::runtime_error
  {
  public:
    using std::runtime_error::runtime_error;
  };

  /// The run was stopped by a signal (core/interrupt.h) before it converged; like ConvergenceError,
  /// what was written so far is kept.
  class Interrupted : public ConvergenceError
  {
  public:
    Interrupted(const std::string &what, const int signal)
        : ConvergenceError(what)
        , signal(signal)
    {
    }

    /// 128 + the signal number, the shell's convention for a process ended by a signal.
    int
    exit_status() const
    {
      return 128 + signal;
    }

  private:
    int signal;
  };

  /// A solver that failed before the run had anything to write (the ngf loading increment): exit
  /// status 3 as for ConvergenceError, but the output directory is left as it was (an earlier
  /// run's results are not replaced by an unloaded body).
  class NoResults : public ConvergenceError
  {
  public:
    using ConvergenceError::ConvergenceError;
  };

  /// The line a run that kept its results ends with, on the console (stderr) and as the last line
  /// of its log.txt: "granflow: not converged: ..." or "granflow: interrupted: ...".
  inline std::string
  ending_line(const ConvergenceError &e)
  {
    return std::string("granflow: ") +
           (dynamic_cast<const Interrupted *>(&e) ? "interrupted: " : "not converged: ") + e.what();
  }

  /// Exit status of the command line for each outcome.
  namespace exit_status
  {
    constexpr int success          = 0;
    constexpr int internal_error   = 1;
    constexpr int bad_input        = 2;
    constexpr int not_converged    = 3;
  } // namespace exit_status
} // namespace granflow
