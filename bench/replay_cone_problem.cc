// Replays a dumped cone problem (Solver/Dump cone problem) with each inner solver and writes the
// wall time, fixed-point iterations and time per iteration as JSON (sand6's d6_solvePrimal idea).
#include "solvers/cone_problem.h"

#include <nlohmann/json.hpp>

#include <cstdlib>
#include <iostream>
#include <sstream>

int
main(int argc, char **argv)
{
  using namespace granflow::solvers;
  if (argc < 2)
    {
      std::cerr << "usage: replay_cone_problem PROBLEM.bin [tolerance] [pg|apgd|spg|ip ...]\n"
                   "  (ip: the interior-point method on the whole problem)\n"
                   "  (GRANFLOW_REPLAY_MAX_SECONDS limits each solve; GRANFLOW_REPLAY_LOG prints "
                   "tables)\n";
      return 2;
    }
  const ConeProblemData    data      = load_cone_problem(argv[1]);
  const double             tolerance = argc > 2 ? std::stod(argv[2]) : 1e-6;
  std::vector<std::string> names;
  for (int i = 3; i < argc; ++i)
    names.emplace_back(argv[i]);
  if (names.empty())
    names = {"pg", "apgd", "spg"};
  nlohmann::json results = nlohmann::json::array();
  for (const auto &name : names)
    {
      ConeSolverOptions options;
      if (name == "ip")
        options.method = ConeMethod::interior_point;
      else
        options.inner_solver = parse_inner_solver(name);
      options.tolerance            = tolerance;
      options.residual             = ResidualKind::fischer_burmeister;
      options.max_outer_iterations = 1000;
      options.max_inner_iterations = 300;
      if (const char *t = std::getenv("GRANFLOW_REPLAY_MAX_SECONDS"))
        options.max_seconds = std::atof(t);
      if (std::getenv("GRANFLOW_REPLAY_LOG"))
        options.log = &std::cerr;
      ConeSolution solution;
      const auto   stats = solve_cone_problem(data, options, solution);
      // Wall time at which the residual first fell to each decade (null: never): how far the
      // fixed point gets, and how fast, when it stalls short of the tolerance.
      nlohmann::json reached = nlohmann::json::object();
      for (const double level : {1e-2, 1e-3, 1e-4, 1e-5, 1e-6})
        {
          nlohmann::json t = nullptr;
          for (std::size_t k = 0; k < stats.residual_history.size(); ++k)
            if (stats.residual_history[k] <= level)
              {
                t = stats.time_factorize + stats.time_history[k];
                break;
              }
          std::ostringstream key;
          key << level;
          reached[key.str()] = t;
        }
      results.push_back({{"method", name == "ip" ? "interior point" : "fixed point"},
                         {"inner_solver", name == "ip" ? "" : name},
                         {"time_to_residual_s", reached},
                         {"converged", stats.converged},
                         {"residual", stats.residual},
                         {"tolerance", tolerance},
                         {"time_factorize_s", stats.time_factorize},
                         {"time_solve_s", stats.time_solve},
                         {"time_total_s", stats.time_factorize + stats.time_solve},
                         {"fixed_point_iterations", stats.outer_iterations},
                         {"inner_iterations", stats.inner_iterations},
                         {"W_applications", stats.operator_applications},
                         {"time_per_fixed_point_iteration_s",
                          stats.time_solve / std::max(1u, stats.outer_iterations)}});
    }
  std::cout << results.dump(2) << '\n';
  return 0;
}
