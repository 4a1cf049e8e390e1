#include "core/errors.h"

namespace granflow
{
  InputError::InputError(const std::string &file, const std::string &entry, const std::string &what)
      : std::runtime_error(file + ": entry '" + entry + "': " + what)
      , entry_(entry)
      , detail_(what)
  {}

  InputError::InputError(const std::string &message)
    : std::runtime_error(message)
  {}
} // namespace granflow
