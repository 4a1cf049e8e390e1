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
  Logger::stamp(const std::string &text)
  {
    last_progress = std::chrono::steady_clock::now();
    if (echo)
      std::cout << "  [" << static_cast<int>(elapsed()) << " s] " << text << std::endl;
  }

  void
  Logger::progress(const std::string &text)
  {
    const auto since = std::chrono::steady_clock::now() - last_progress;
    if (std::chrono::duration<double>(since).count() >= progress_interval)
      stamp(text);
  }

  void
  Logger::phase(const std::string &text)
  {
    if (elapsed() >= 1.)
      stamp(text);
  }

  double
  Logger::elapsed() const
  {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  }
} // namespace granflow
