#include "core/run_report.h"

#include "core/errors.h"
#include "core/interrupt.h"

#include <utility>

namespace granflow
{
  RunReport::RunReport(Logger &log, const OutputDirectory &out, std::string model)
      : log(log)
      , out(out)
      , model(std::move(model))
  {
  }

  void
  RunReport::warn(const std::string &text)
  {
    log.print(model + ": warning: " + text + "\n");
    warnings_.push_back(text);
  }

  void
  RunReport::finish(nlohmann::json &summary, const std::string &failure,
                    const bool interrupted) const
  {
    summary["warnings"]           = warnings_;
    summary["timings"]            = timings;
    summary["timings"]["total_s"] = log.elapsed();
    out.write_json("summary.json", summary);
    if (failure.empty())
      return;
    if (interrupted)
      throw Interrupted(failure, interrupt::signal_number());
    throw ConvergenceError(failure);
  }
} // namespace granflow
