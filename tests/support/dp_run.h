// Test support: running a shipped dp case through the library, with overrides, into a fresh
// directory under the test's temporary directory.
#pragma once

#include "core/output.h"
#include "models/dp/dp_model.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <string>
#include <vector>

namespace granflow::test
{
  /// The summary of cases/daviet2016/`case_name` run with `overrides`; its "dir" is the output
  /// directory (`name` under the test's temporary directory).
  inline nlohmann::json
  run_dp(const std::string &case_name, const std::vector<granflow::Override> &overrides,
         const std::string &name)
  {
    const std::string case_file =
        std::string(GRANFLOW_SOURCE_DIR) + "/cases/daviet2016/" + case_name;
    const auto        parameters = granflow::dp::load_parameters(case_file, overrides);
    const std::string dir        = ::testing::TempDir() + "/granflow_" + name;
    std::filesystem::remove_all(dir);
    granflow::OutputDirectory out(dir);
    granflow::Logger          log(out.file("log.txt"), false);
    auto                      summary = granflow::dp::run(parameters, out, log).summary;
    out.commit();
    summary["dir"] = dir;
    return summary;
  }
} // namespace granflow::test
