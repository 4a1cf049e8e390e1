#include "core/logger.h"

#include <iostream>

namespace granflow
{
  Logger::Logger(const std::string &log_file, const bool echo_to_console)
    : file(log_file)
    , echo(echo_to_console)
    , start(std::chrono::steady_clock::now())
    , last_progress(start)
  {}

  void
  Logger::print(const std::string &text)
  {
    file << text << std::flush;
    if (echo)
      std::cout << text << std::flush;
  }

  void
  Logger::flush_table()
  {
    file << std::flush;
  }

  void
  Logger::progress(const std::string &text)
  {
    const auto now = std::chrono::steady_clock::now();
    if (std::chrono::duration<double>(now - last_progress).count() < progress_interval)
      return;
    last_progress = now;
    if (echo)
      std::cout << "  [" << static_cast<int>(elapsed()) << " s] " << text << std::endl;
  }

  void
  Logger::phase(const std::string &text)
  {
    if (elapsed() < 1.)
      return;
    last_progress = std::chrono::steady_clock::now();
    if (echo)
      std::cout << "  [" << static_cast<int>(elapsed()) << " s] " << text << std::endl;
  }

  double
  Logger::elapsed() const
  {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  }
} // namespace granflow
