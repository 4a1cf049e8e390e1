#include "core/interrupt.h"

#include <csignal>

#include <unistd.h>

namespace granflow::interrupt
{
  namespace
  {
    volatile std::sig_atomic_t received = 0;

    extern "C" void
    handle(const int signal)
    {
      received = signal;
      // The next one gets the default action: a user who presses Ctrl-C twice means it.
      std::signal(signal, SIG_DFL);
      // Said at once (write(2) is async-signal-safe), so that nobody presses it twice unawares.
      constexpr char message[] =
          "\ngranflow: stopping at the next iteration; what has been computed "
          "will be written (Ctrl-C again to quit at once)\n";
      [[maybe_unused]] const auto written = ::write(STDERR_FILENO, message, sizeof(message) - 1);
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
} // namespace granflow::interrupt
