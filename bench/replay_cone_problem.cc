// Replays a dumped cone problem (Solver/Dump cone problem) with each inner solver and writes the
// wall time, fixed-point iterations and time per iteration as JSON (sand6's d6_solvePrimal idea).
//
// The command line is checked before any work (exit 2, one message). A method that fails on the
// problem (the interior point where Bi > 0, say) gets an "error" entry and the others still run
// (exit 3 at the end); Ctrl-C or SIGTERM ends the current solve at its next iteration and prints
// what was measured so far (exit 128 + the signal). The JSON is printed in every one of these
// cases.
#include "core/interrupt.h"
#include "core/parameters.h"
#include "solvers/cone_problem.h"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <functional>
#include <iostream>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <vector>

namespace
{
  constexpr char usage[] =
      "usage: replay_cone_problem PROBLEM.bin [tolerance] [pg|apgd|spg|ip|fp-ip ...]\n"
      "  (ip: the interior point, split form then whole problem; fp-ip: the fixed point with\n"
      "   interior-point inner solves; default methods: pg apgd spg)\n"
      "  (GRANFLOW_REPLAY_MAX_SECONDS limits each solve; GRANFLOW_REPLAY_LOG prints tables)\n"
      "  (GRANFLOW_REPLAY_UNITS=paper: the residual of Daviet (35), lambda against gamma with its\n"
      "   quadrature weight, instead of the run's units of stress)\n"
      "  (GRANFLOW_REPLAY_TUNE='interior_point.short_steps=10, fixed_point.spg_memory=20': the\n"
      "   solvers' tunables, FixedPointTunables and InteriorPointTunables in\n"
      "   src/solvers/cone_problem.h, without recompiling; fixed_point.anderson_depth,\n"
      "   .max_outer_iterations (1000 unless set),\n"
      "   .max_inner_iterations and .inner_tolerance_factor set the fixed point's own options)\n";

  /// A positive finite number written in full ("1e-6", not "1e-6x"), or nothing.
  std::optional<double>
  parse_positive(const char *text)
  {
    try
      {
        std::size_t  used  = 0;
        const double value = std::stod(text, &used);
        if (used == std::string(text).size() && std::isfinite(value) && value > 0.)
          return value;
      }
    catch (const std::exception &)
      {
      }
    return std::nullopt;
  }

  /// One of the solvers' tunables, by the name GRANFLOW_REPLAY_TUNE gives it.
  struct Tunable
  {
    std::string                                                         name;
    bool                                                                count; // a whole number
    std::function<void(granflow::solvers::ConeSolverOptions &, double)> set;
    double least = 0.; // the smallest value accepted
  };

  template <typename Group, typename T>
  Tunable
  tunable(const std::string &group_name, Group granflow::solvers::ConeSolverOptions::*group,
          const char *name, T Group::*field)
  {
    return {group_name + "." + name, std::is_integral_v<T>,
            [=](granflow::solvers::ConeSolverOptions &o, const double v) {
              (o.*group).*field = static_cast<T>(v);
            }};
  }

  /// A field of ConeSolverOptions itself, named "fixed_point.NAME": how the outer loop drives
  /// its inner solves (anderson_depth = 0 is the plain Algorithm 1 of the paper).
  template <typename T>
  Tunable
  option_tunable(const char *name, T granflow::solvers::ConeSolverOptions::*field,
                 const double least = 0.)
  {
    return {std::string("fixed_point.") + name, std::is_integral_v<T>,
            [=](granflow::solvers::ConeSolverOptions &o, const double v) {
              o.*field = static_cast<T>(v);
            },
            least};
  }

  std::vector<Tunable>
  tunables()
  {
    using namespace granflow::solvers;
    using F                                                 = FixedPointTunables;
    using I                                                 = InteriorPointTunables;
    const std::string            fp                         = "fixed_point";
    const std::string            ip                         = "interior_point";
    constexpr FixedPointTunables ConeSolverOptions::*fpg    = &ConeSolverOptions::fixed_point;
    constexpr InteriorPointTunables ConeSolverOptions::*ipg = &ConeSolverOptions::interior_point;
    return {option_tunable("anderson_depth", &ConeSolverOptions::anderson_depth),
            // the limit on the outer iterations (1000 in a replay), of every method: the
            // fixed point's iterations, or the interior point's and the chain's fixed-point steps
            option_tunable("max_outer_iterations", &ConeSolverOptions::max_outer_iterations, 1.),
            // An inner solve of no iterations would return its starting point at every step.
            option_tunable("max_inner_iterations", &ConeSolverOptions::max_inner_iterations, 1.),
            option_tunable("inner_tolerance_factor", &ConeSolverOptions::inner_tolerance_factor),
            tunable(fp, fpg, "stall_ratio", &F::stall_ratio),
            tunable(fp, fpg, "stalls_before_tightening", &F::stalls_before_tightening),
            tunable(fp, fpg, "max_inner_growth", &F::max_inner_growth),
            tunable(fp, fpg, "min_inner_tolerance_factor", &F::min_inner_tolerance_factor),
            tunable(fp, fpg, "inner_tolerance_floor", &F::inner_tolerance_floor),
            tunable(fp, fpg, "stagnation_min_iterations", &F::stagnation_min_iterations),
            tunable(fp, fpg, "stagnation_ratio", &F::stagnation_ratio),
            tunable(fp, fpg, "anderson_regularization", &F::anderson_regularization),
            tunable(fp, fpg, "norm_estimate_iterations", &F::norm_estimate_iterations),
            tunable(fp, fpg, "norm_margin", &F::norm_margin),
            tunable(fp, fpg, "apgd_min_lipschitz_fraction", &F::apgd_min_lipschitz_fraction),
            tunable(fp, fpg, "apgd_lipschitz_decrease", &F::apgd_lipschitz_decrease),
            tunable(fp, fpg, "spg_memory", &F::spg_memory),
            tunable(fp, fpg, "spg_armijo", &F::spg_armijo),
            tunable(fp, fpg, "spg_max_step", &F::spg_max_step),
            tunable(ip, ipg, "split_form", &I::split_form),
            tunable(ip, ipg, "whole_form_after_stall", &I::whole_form_after_stall),
            tunable(ip, ipg, "fixed_point_after_stall", &I::fixed_point_after_stall),
            tunable(ip, ipg, "step_fraction", &I::step_fraction),
            tunable(ip, ipg, "centering_exponent", &I::centering_exponent),
            tunable(ip, ipg, "initial_margin", &I::initial_margin),
            tunable(ip, ipg, "warm_start_shift", &I::warm_start_shift),
            tunable(ip, ipg, "short_step", &I::short_step),
            tunable(ip, ipg, "short_steps", &I::short_steps),
            tunable(ip, ipg, "stagnation_iterations", &I::stagnation_iterations),
            tunable(ip, ipg, "stagnation_ratio", &I::stagnation_ratio),
            tunable(ip, ipg, "whole_form_patience", &I::whole_form_patience),
            tunable(ip, ipg, "reduced_system", &I::reduced_system),
            tunable(ip, ipg, "refinement_steps", &I::refinement_steps),
            tunable(ip, ipg, "reduced_accuracy", &I::reduced_accuracy)};
  }

  int
  bad_input(const std::string &message)
  {
    std::cerr << "replay_cone_problem: " << message << '\n';
    return 2;
  }

  nlohmann::json
  measurements(const granflow::solvers::ConeSolverStats &stats, const double tolerance,
               const bool chain)
  {
    // Wall time and number of outer iterations after which the residual first fell to each
    // decade (null: never): how far the fixed point gets, and how fast, when it stalls short of
    // the tolerance. The iterations compare with Table 2's n.
    nlohmann::json reached    = nlohmann::json::object();
    nlohmann::json iterations = nlohmann::json::object();
    for (const double level : {1e-2, 1e-3, 1e-4, 1e-5, 1e-6})
      {
        nlohmann::json t = nullptr, n = nullptr;
        for (std::size_t k = 0; k < stats.residual_history.size(); ++k)
          if (stats.residual_history[k] <= level)
            {
              t = stats.time_factorize + stats.time_history[k];
              n = k; // the history's first entry is the starting iterate's
              break;
            }
        std::ostringstream key;
        key << level;
        reached[key.str()]    = t;
        iterations[key.str()] = n;
      }
    nlohmann::json result = {
        {"time_to_residual_s", reached},
        {"iterations_to_residual", iterations},
        {"converged", stats.converged},
        {"interrupted", stats.interrupted},
        {"stalled", stats.stalled},
        {"timed_out", stats.timed_out},
        {"residual", stats.residual},
        {"tolerance", tolerance},
        {"time_factorize_s", stats.time_factorize},
        {"time_solve_s", stats.time_solve},
        {"time_total_s", stats.time_factorize + stats.time_solve},
        {"fixed_point_iterations", stats.outer_iterations},
        {"stall_reason", stats.stall_reason},
        {"inner_iterations", stats.inner_iterations},
        // interior point: its fixed-point stage's steps, in fixed_point_iterations
        {"fixed_point_steps", stats.fixed_point_steps},
        {"W_applications", stats.operator_applications}};
    if (!chain)
      {
        result["time_per_fixed_point_iteration_s"] =
            stats.time_solve / std::max(1u, stats.outer_iterations);
        return result;
      }
    // The interior point's chain counts its interior-point iterations (split and whole forms)
    // and its fixed-point stage's steps together in outer_iterations, and a step costs a whole
    // interior-point solve: each gets its own time per iteration (null: none taken). The stage's
    // records are the history's last fixed_point_steps + 1 (its start, then one per step), on the
    // chain's clock, and the forms' last record is the one before; the stage's time, from there
    // to the end, includes its setup (it factorises A again).
    const std::size_t  steps     = stats.fixed_point_steps;
    const std::size_t  records   = stats.time_history.size();
    const unsigned int ip_its    = stats.outer_iterations - stats.fixed_point_steps;
    const double       forms_end = steps > 0 && records >= steps + 2
                                       ? stats.time_history[records - steps - 2]
                                       : stats.time_solve;
    const auto         per = [](const double time, const std::size_t count) -> nlohmann::json {
      if (count == 0)
        return nullptr;
      return time / static_cast<double>(count);
    };
    result["interior_point_iterations"]           = ip_its;
    result["time_per_interior_point_iteration_s"] = per(stats.time_factorize + forms_end, ip_its);
    result["time_per_fixed_point_step_s"]         = per(stats.time_solve - forms_end, steps);
    return result;
  }
} // namespace

int
main(int argc, char **argv)
{
  using namespace granflow;
  using namespace granflow::solvers;
  // First of all: a Ctrl-C that came before would be lost (a script's background job starts with
  // SIGINT ignored); one that comes while the dump is read ends the first solve at once.
  interrupt::install();
  if (argc < 2)
    return bad_input("no problem file (usage: replay_cone_problem PROBLEM.bin [tolerance] "
                     "[pg|apgd|spg|ip|fp-ip ...]; --help for more)");
  if (std::string(argv[1]) == "--help")
    {
      std::cout << usage;
      return 0;
    }

  double tolerance = 1e-6;
  if (argc > 2)
    {
      const auto value = parse_positive(argv[2]);
      if (!value)
        return bad_input("tolerance '" + std::string(argv[2]) +
                         "' is not a positive number (for example 1e-6)");
      tolerance = *value;
    }
  std::vector<std::string> names;
  for (int i = 3; i < argc; ++i)
    {
      const std::string name = argv[i];
      if (name != "pg" && name != "apgd" && name != "spg" && name != "ip" && name != "fp-ip")
        return bad_input("unknown method '" + name + "': expected pg, apgd, spg, ip or fp-ip");
      names.push_back(name);
    }
  if (names.empty())
    names = {"pg", "apgd", "spg"};
  double max_seconds = 0.; // 0, unset or empty: no limit, as Solver/Max seconds = 0
  if (const char *t = std::getenv("GRANFLOW_REPLAY_MAX_SECONDS"); t && *t && std::string(t) != "0")
    {
      const auto value = parse_positive(t);
      if (!value)
        return bad_input("GRANFLOW_REPLAY_MAX_SECONDS='" + std::string(t) +
                         "' is not a number of seconds (> 0, or 0 for no limit)");
      max_seconds = *value;
    }

  // The residual's units: the run's (lambda against the viscous stress of the strain rate, the
  // scales the dump carries) or the paper's: Daviet (34b)-(35b) make gamma_q = R^{+T} B u, which
  // for the square, block-diagonal R of P1d at its quadrature points is w_q D(u)(x_q), the strain
  // rate times the point's weight (what granflow compared lambda with before session 12). Table 2
  // measures its tolerance on (35).
  bool paper_units = false;
  if (const char *u = std::getenv("GRANFLOW_REPLAY_UNITS"); u && *u)
    {
      if (std::string(u) != "paper" && std::string(u) != "run")
        return bad_input("GRANFLOW_REPLAY_UNITS='" + std::string(u) + "': expected paper or run");
      paper_units = std::string(u) == "paper";
    }

  // GRANFLOW_REPLAY_TUNE: "name=value, ..." over the tunables' defaults, each a finite number
  // >= 0 (a whole one for counts), each name at most once.
  ConeSolverOptions tuned;
  tuned.max_outer_iterations   = 1000;
  nlohmann::json    tuned_json = nlohmann::json::object();
  if (const char *t = std::getenv("GRANFLOW_REPLAY_TUNE"); t && *t)
    {
      const std::vector<Tunable> known = tunables();
      std::stringstream          list(t);
      std::string                item;
      while (std::getline(list, item, ','))
        {
          const auto        eq   = item.find('=');
          const std::string name = trim(item.substr(0, eq));
          const auto        it   = std::find_if(known.begin(), known.end(),
                                                [&](const Tunable &k) { return k.name == name; });
          if (eq == std::string::npos || it == known.end())
            {
              std::string names;
              for (const auto &k : known)
                names += (names.empty() ? "" : ", ") + k.name;
              return bad_input("GRANFLOW_REPLAY_TUNE: '" + trim(item) +
                               "' is not name=value with a known name: expected one of " + names);
            }
          if (tuned_json.contains(name))
            return bad_input("GRANFLOW_REPLAY_TUNE: " + name + " is set twice");
          const std::string text  = trim(item.substr(eq + 1));
          double            value = -1.; // refused below
          try
            {
              value = parse_number(text);
            }
          catch (const std::exception &)
            {
            }
          if (!(std::isfinite(value) && value >= it->least) ||
              (it->count && (value != std::floor(value) || value > 1e9)))
            {
              std::ostringstream expected;
              expected << (it->count ? "a whole number >= " : "a finite number >= ") << it->least;
              return bad_input("GRANFLOW_REPLAY_TUNE: " + name + "='" + text + "': expected " +
                               expected.str());
            }
          it->set(tuned, value);
          tuned_json[name] = value;
        }
    }

  ConeProblemData data;
  try
    {
      std::ifstream in(argv[1], std::ios::binary);
      if (!in)
        return bad_input("cannot read cone problem '" + std::string(argv[1]) + "'");
      data = read_cone_problem(in);
    }
  catch (const std::exception &e)
    {
      return bad_input("'" + std::string(argv[1]) + "' " + e.what());
    }
  if (paper_units)
    data.gamma_scale.clear();

  nlohmann::json results = nlohmann::json::array();
  bool           failed  = false;
  for (const auto &name : names)
    {
      // ip: the interior point; the others name the fixed point's steps (fp-ip: "ip" ones).
      const std::string inner   = name == "ip" ? "" : name == "fp-ip" ? "ip" : name;
      nlohmann::json    entry   = {{"method", inner.empty() ? "interior point" : "fixed point"},
                                   {"inner_solver", inner},
                                   {"residual_units", paper_units ? "paper" : "run"}};
      ConeSolverOptions options = tuned;
      if (!tuned_json.empty())
        entry["tunables"] = tuned_json;
      if (inner.empty())
        options.method = ConeMethod::interior_point;
      else
        options.inner_solver = parse_inner_solver(inner);
      options.tolerance            = tolerance;
      options.residual             = ResidualKind::fischer_burmeister;
      options.max_seconds          = max_seconds;
      options.stop_requested       = interrupt::requested;
      if (std::getenv("GRANFLOW_REPLAY_LOG"))
        options.log = &std::cerr;
      try
        {
          ConeSolution solution;
          entry.update(measurements(solve_cone_problem(data, options, solution), tolerance, inner.empty()));
        }
      catch (const std::exception &e)
        {
          entry["error"] = e.what();
          std::cerr << "replay_cone_problem: " << name << ": " << e.what() << '\n';
          failed = true;
        }
      results.push_back(entry);
      if (interrupt::requested())
        break;
    }
  std::cout << results.dump(2) << '\n';
  if (interrupt::requested())
    return 128 + interrupt::signal_number();
  return failed ? 3 : 0;
}
