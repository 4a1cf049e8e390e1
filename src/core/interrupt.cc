#include "core/interrupt.h"

#include <algorithm>
#include <atomic>
#include <csignal>

#include <unistd.h>

namespace granflow::interrupt
{
  namespace
  {
    volatile std::sig_atomic_t received = 0;
    volatile std::sig_atomic_t at_once       = 0;  // inside a BeforeResults scope
    char                       outcome[4096] = ""; // its outcome, written before at_once is set

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
      say(" before anything was computed (while meshing, setting up or factorising): ");
      say(outcome);
      say("\n");
      ::_exit(128 + signal);
    }

    extern "C" void
    handle(const int signal)
    {
      if (at_once)
        stop_at_once(signal);
      received = signal;
      // The next one gets the default action: a user who presses Ctrl-C twice means it.
      std::signal(signal, SIG_DFL);
      // Said at once (write(2) is async-signal-safe), so that nobody presses it twice unawares.
      say("\ngranflow: stopping at the next iteration; what has been computed will be written "
          "(Ctrl-C again to quit at once)\n");
    }
  } // namespace

  void
  install()
  {
    std::signal(SIGINT, handle);
    std::signal(SIGTERM, handle);
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
    std::atomic_signal_fence(std::memory_order_seq_cst); // the handler sees the whole text
    at_once = 1;
    if (received != 0)
      stop_at_once(received);
  }

  BeforeResults::~BeforeResults()
  {
    at_once = 0;
  }
} // namespace granflow::interrupt
