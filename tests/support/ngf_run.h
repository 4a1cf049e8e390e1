// Test support: one ngf run into a fresh directory under the test's temporary directory.
#pragma once

#include "core/output.h"
#include "models/ngf/ngf_model.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <string>

namespace granflow::test
{
  /// Runs `parameters` into TempDir()/granflow_<name> (emptied first) and returns the summary, with
  /// the directory under "output_directory".
  inline nlohmann::json
  run_ngf(const ngf::Parameters &parameters, const std::string &name)
  {
    const std::string dir = ::testing::TempDir() + "/granflow_" + name;
    std::filesystem::remove_all(dir);
    OutputDirectory out(dir);
    Logger          log(out.file("log.txt"), false);
    auto            summary = ngf::run(parameters, out, log).summary;
    out.commit();
    summary["output_directory"] = dir;
    return summary;
  }
} // namespace granflow::test
