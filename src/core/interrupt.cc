#include "core/interrupt.h"

#include <algorithm>
#include <atomic>
#include <csignal>
#include <cstddef>

#include <unistd.h>

namespace granflow::interrupt
{
  namespace
  {
    // Atomics, not volatile sig_atomic_t: the handler may run on any thread (Gmsh meshes with
    // OpenMP), and lock-free atomics are safe in it (C++17 [support.signal]).
    std::atomic<int> received{0};
    std::atomic<int> at_once{0};         // inside a BeforeResults scope
    char             outcome[4096] = ""; // its outcome, written before at_once is set
    static_assert(std::atomic<int>::is_always_lock_free);

    void
    say(const char *text)
    {
      std::size_t n = 0;
      while (text[n] != '\0')
        ++n;
      [[maybe_unused]] const auto written = ::write(STDERR_FILENO, text, n);
    }

    /// Ends the process for `signal` without running destructors or flushing streams: only
    /// async-signal-safe calls (write(2), _exit(2)), as this runs in a signal handler.
    [[noreturn]] void
    stop_at_once(const int signal)
    {
      say("\ngranflow: stopped by ");
      say(signal == SIGINT ? "SIGINT" : signal == SIGTERM ? "SIGTERM" : "a signal");
      say(" before it had results to write (while meshing, setting up, or in the first "
          "iteration): ");
      say(outcome);
      say("\n");
      ::_exit(128 + signal);
    }

    extern "C" void
    handle(const int signal)
    {
      // received first, at_once second, and the reverse in BeforeResults(): with sequentially
      // consistent atomics a signal arriving while a scope begins is seen by one of the two.
      received = signal;
      if (at_once)
        stop_at_once(signal);
      // The next one gets the default action: a user who presses Ctrl-C twice means it.
      std::signal(signal, SIG_DFL);
      // Said at once (write(2) is async-signal-safe), so that nobody presses it twice unawares.
      say("\ngranflow: stopping at the next iteration; what has been computed will be written ");
      say(signal == SIGINT ? "(Ctrl-C again to quit at once)\n"
                           : "(a second SIGTERM quits at once)\n");
    }
  } // namespace

  void
  install()
  {
    std::signal(SIGINT, handle);
    std::signal(SIGTERM, handle);
    // A reader that closes its end of standard output (`granflow run ... | head -1`) must not
    // end the run unannounced, with DIR left staged: the writes to the pipe then fail instead
    // (the output to it is lost, log.txt has it), and the run goes on to write DIR.
    std::signal(SIGPIPE, SIG_IGN);
  }

  bool
  requested()
  {
    return received != 0;
  }

  int
  signal_number()
  {
    return received;
  }

  const char *
  signal_name()
  {
    switch (received)
      {
      case SIGINT:
        return "SIGINT";
      case SIGTERM:
        return "SIGTERM";
      default:
        return "a signal";
      }
  }

  BeforeResults::BeforeResults(const std::string &text)
  {
    const std::size_t n = std::min(text.size(), sizeof(outcome) - 1);
    std::copy_n(text.begin(), n, outcome);
    outcome[n] = '\0';
    at_once    = 1; // a release of the text above to the handler, which reads at_once first
    if (const int signal = received; signal != 0)
      stop_at_once(signal);
  }

  BeforeResults::~BeforeResults()
  {
    at_once = 0;
  }
} // namespace granflow::interrupt
