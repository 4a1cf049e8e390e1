// The models granflow knows, for the command line: name, description, parameters, run.
#pragma once

#include "core/parameters.h"

#include <nlohmann/json.hpp>

#include <functional>
#include <string>
#include <vector>

namespace granflow
{
  struct RunRequest
  {
    std::string           case_file;
    std::vector<Override> overrides;
    std::string           output_directory; // empty: results/<case file stem>
    bool                  quiet = false;
  };

  struct ModelInfo
  {
    std::string                                    name;
    std::string                                    description;
    std::function<void(dealii::ParameterHandler &)> print_parameters;
    /// Returns the summary; throws InputError / ConvergenceError.
    std::function<nlohmann::json(const RunRequest &)> run;
  };

  const std::vector<ModelInfo> &
  models();

  /// The models' names as a message lists them: "dp, ngf".
  std::string
  model_names();

  /// Reads the case file's Model entry and runs it.
  nlohmann::json
  run_case(const RunRequest &request);
} // namespace granflow
