// What a run reports besides its results (DESIGN.md "Output directory"): its warnings, said in the
// log as they arise and listed in summary.json, and the end of the run, where summary.json is
// written before a failure is thrown, so that a run that did not converge leaves complete output
// and then exits with its status (errors.h).
#pragma once

#include "core/logger.h"
#include "core/output.h"

#include <nlohmann/json.hpp>

#include <string>
#include <vector>

namespace granflow
{
  class RunReport
  {
  public:
    /// `model` is the prefix of the log's warning lines ("dp", "ngf").
    RunReport(Logger &log, const OutputDirectory &out, std::string model);

    /// Logs "<model>: warning: `text`" and keeps it for summary.json's "warnings".
    void
    warn(const std::string &text);

    const std::vector<std::string> &
    warnings() const
    {
      return warnings_;
    }

    /// Seconds spent in named parts of the run: summary.json's "timings", to which finish() adds
    /// "total_s", the time since the log began.
    nlohmann::json timings = nlohmann::json::object();

    /// Adds "warnings" and "timings" to `summary` and writes it to summary.json. Then, if
    /// `failure` is not empty, throws it, as Interrupted (exit status 128 + the signal) if a signal
    /// stopped the run, else as ConvergenceError (exit status 3).
    void
    finish(nlohmann::json &summary, const std::string &failure = "",
           bool interrupted = false) const;

  private:
    Logger                  &log;
    const OutputDirectory   &out;
    std::string              model;
    std::vector<std::string> warnings_;
  };
} // namespace granflow
