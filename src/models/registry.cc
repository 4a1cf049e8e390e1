#include "models/registry.h"

#include "core/errors.h"
#include "core/logger.h"
#include "core/output.h"
#include "models/dp/dp_model.h"
#include "models/ngf/ngf_model.h"

#include <algorithm>
#include <filesystem>
#include <iostream>

namespace granflow
{
  namespace
  {
    std::string
    default_output_directory(const std::string &case_file)
    {
      return (std::filesystem::path("results") / std::filesystem::path(case_file).stem()).string();
    }

    /// Reads, validates, runs and commits one case of a model whose namespace has Parameters and
    /// run().
    template <typename ModelParameters, typename Run>
    nlohmann::json
    run_model(const RunRequest &request, const std::string &model_name, const Run &run)
    {
      ModelParameters          parameters;
      dealii::ParameterHandler prm;
      read_case(parameters, prm, request.case_file, request.overrides);

      const std::string  dir = request.output_directory.empty()
                                   ? default_output_directory(request.case_file)
                                   : request.output_directory;
      OutputDirectory    out(dir);
      if (out.would_replace(request.case_file))
        throw InputError((request.output_directory.empty() ? "output directory " : "--output ") +
                         dir +
                         ": the run writes its own files there, and would "
                         "replace the case file " +
                         request.case_file +
                         " (expected an output directory that does not hold the case file under "
                         "a name the run writes, such as parameters.prm)");
      Logger             log(out.file("log.txt"), !request.quiet);
      std::ostringstream used;
      prm.print_parameters(used, dealii::ParameterHandler::Text);
      out.write_text("parameters.prm", used.str());
      log.print("granflow: case " + request.case_file + " (model " + model_name + ") -> " + dir +
                "\n");
      // Moves the results into the target. A failure part-way (a rename) leaves the target
      // mixing this run's files with an earlier run's: said, and the rest is kept in staging.
      const auto commit = [&] {
        try
          {
            out.commit();
          }
        catch (const std::exception &e)
          {
            out.keep_staging();
            bool            unmoved = false;
            std::error_code ec;
            for (std::filesystem::recursive_directory_iterator f(out.path(), ec), end;
                 !ec && f != end; f.increment(ec))
              unmoved = unmoved || f->is_regular_file();
            throw std::runtime_error(
                std::string(e.what()) + " (while moving the results into " + dir +
                (out.partly_committed()
                     ? ", which may now mix this run's files with an earlier run's, until the "
                       "next run into it removes them"
                     : ": nothing was moved, " + dir + " is as it was") +
                (unmoved ? "; what was not moved is in " + out.path() : std::string()) + ")");
          }
      };
      nlohmann::json summary;
      try
        {
          summary = run(parameters, out, log).summary;
        }
      catch (const InputError &)
        {
          throw; // nothing is committed: the target directory stays as it was
        }
      catch (const NoResults &e)
        {
          out.keep_staging(); // the target stays as it was
          const NoResults said(std::string(e.what()) +
                               "; nothing was computed: " + out.left_as_it_was());
          log.table() << ending_line(said) << '\n';
          log.flush_table();
          throw said;
        }
      catch (const ConvergenceError &e) // Interrupted included
        {
          // the console's last line, with the reason and the remedy, is the log's too
          log.table() << ending_line(e) << '\n';
          log.flush_table();
          commit(); // what was written so far is kept
          throw;
        }
      catch (const std::exception &e)
        {
          // An internal error: this run's log is kept beside the target, which stays as it was.
          out.keep_staging();
          const std::runtime_error said(std::string(e.what()) + " (" + out.left_as_it_was() + ")");
          log.table() << "granflow: internal error: " << said.what() << '\n';
          log.flush_table();
          throw said;
        }
      commit();
      summary["output_directory"] = out.target();
      return summary;
    }
  } // namespace

  const std::vector<ModelInfo> &
  models()
  {
    static const std::vector<ModelInfo> list = {
        {"dp",
         "nonsmooth Drucker-Prager DP(mu, Bi) creeping flow (Daviet & Bertails-Descoubes 2016)",
         [](dealii::ParameterHandler &prm) {
           dp::Parameters p;
           p.declare(prm);
         },
         [](const RunRequest &r) { return run_model<dp::Parameters>(r, "dp", dp::run); }},
        {"ngf",
         "nonlocal granular fluidity, finite-deformation elasto-viscoplasticity (Henann & Kamrin "
         "2016)",
         [](dealii::ParameterHandler &prm) {
           ngf::Parameters p;
           p.declare(prm);
         },
         [](const RunRequest &r) { return run_model<ngf::Parameters>(r, "ngf", ngf::run); }}};
    return list;
  }

  std::string
  model_names()
  {
    std::string names;
    for (const auto &m : models())
      names += (names.empty() ? "" : ", ") + m.name;
    return names;
  }

  nlohmann::json
  run_case(const RunRequest &request)
  {
    const std::string name = read_model_name(request.case_file);
    for (const Override &o : request.overrides)
      if (split_list(o.path, '/') == std::vector<std::string>{"Model"} && trim(o.value) != name)
        {
          const std::string other = trim(o.value);
          const auto        known = std::find_if(models().begin(), models().end(),
                                                 [&](const auto &m) { return m.name == other; });
          throw InputError(
              "--set " + o.path + "=" + o.value + ": the model is the case file's (set Model = " +
              name + "), and the entries of one model are not another's: expected " +
              (known != models().end() ? "a case file of that model (`granflow print-parameters " +
                                             other + "` writes one)"
                                       : "no --set Model (the models are " + model_names() + ")"));
        }
    for (const auto &m : models())
      if (m.name == name)
        try
          {
            return m.run(request);
          }
        catch (const InputError &e)
          {
            // found by validate() or while running (a mesh lacking a boundary, a profile line off
            // the mesh, ...): a value from the command line is blamed on its --set
            rethrow_naming_overrides(e, request.case_file, request.overrides);
          }
    throw InputError(request.case_file, "Model",
                     "unknown model '" + name + "': expected one of " + model_names());
  }
} // namespace granflow
