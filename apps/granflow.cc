// granflow command line: run a case file, list the shipped cases, print a model's parameters.
#include "core/errors.h"
#include "core/interrupt.h"
#include "core/parameters.h"
#include "models/registry.h"

#include <deal.II/base/parameter_handler.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <set>
#include <string>
#include <vector>

namespace
{
  const char *usage_commands = R"(granflow: finite-element simulator for dense granular flows

Usage:
  granflow run CASE.prm [--set Section/key=value ...] [--output DIR] [--quiet]
  granflow print-parameters MODEL     every entry with default, range and help
  granflow list-cases                 the case files shipped in cases/
  granflow --help | --version
)";

  const char *usage_results = R"(
Results go to DIR (default results/<case file name without .prm>): solution.pvd (open in ParaView),
summary.json, profiles/*.csv, log.txt. Plot a profile with scripts/plot.

Exit status: 0 success, 2 bad input, 3 a solver did not converge (results so far kept),
130 / 143 stopped by Ctrl-C / SIGTERM (results so far kept; a second Ctrl-C ends at once).
)";

  /// The help text; its list of models is the registry's, so a new model shows up by itself.
  void
  print_usage(std::ostream &out)
  {
    out << usage_commands << "\nModels (the case file's `set Model = ...`):\n";
    for (const auto &m : granflow::models())
      out << "  " << m.name << std::string(m.name.size() < 6 ? 6 - m.name.size() : 1, ' ')
          << m.description << '\n';
    out << usage_results;
  }

  std::filesystem::path
  cases_directory()
  {
    if (std::filesystem::is_directory("cases"))
      return "cases";
    return std::filesystem::path(GRANFLOW_SOURCE_DIR) / "cases";
  }

  int
  list_cases()
  {
    std::vector<std::filesystem::path> files;
    for (const auto &entry : std::filesystem::recursive_directory_iterator(cases_directory()))
      if (entry.path().extension() == ".prm")
        files.push_back(entry.path());
    std::sort(files.begin(), files.end());
    for (const auto &f : files)
      {
        // The first comment line with text in it says what the case is.
        std::ifstream in(f);
        std::string   line, title;
        while (std::getline(in, line))
          if (const auto text = line.find_first_not_of("# \t\r");
              line.rfind("#", 0) == 0 && text != std::string::npos)
            {
              title = line.substr(text);
              break;
            }
        std::cout << f.string() << "\n    " << title << "\n";
      }
    return 0;
  }

  int
  print_parameters(const std::string &model)
  {
    for (const auto &m : granflow::models())
      if (m.name == model)
        {
          dealii::ParameterHandler prm;
          m.print_parameters(prm);
          prm.print_parameters(std::cout, dealii::ParameterHandler::Text);
          return 0;
        }
    throw granflow::InputError("print-parameters: unknown model '" + model + "': expected one of " +
                               granflow::model_names());
  }

  int
  run(const std::vector<std::string> &args)
  {
    granflow::RunRequest request;
    for (std::size_t i = 0; i < args.size(); ++i)
      {
        const std::string &a = args[i];
        if ((a == "--set" || a == "--output") && i + 1 == args.size())
          throw granflow::InputError(a + ": missing value");
        if (a == "--set" || a.rfind("--set=", 0) == 0)
          {
            std::string value = a == "--set" ? args[++i] : a.substr(6);
            // An entry name with blanks, unquoted, reaches us in pieces: "--set Solver/Max outer
            // iterations=5" gives "Solver/Max", "outer" and "iterations=5".
            if (value.find('=') == std::string::npos)
              {
                std::size_t last = i + 1;
                while (last < args.size() && args[last].rfind("--", 0) != 0 &&
                       args[last].find('=') == std::string::npos)
                  ++last;
                if (last < args.size() && args[last].rfind("--", 0) != 0)
                  {
                    for (std::size_t piece = i + 1; piece <= last; ++piece)
                      value += " " + args[piece];
                    throw granflow::InputError(
                        "--set " + value +
                        ": expected Section/key=value as one argument (quote an entry whose name "
                        "has a blank: --set '" +
                        value + "')");
                  }
              }
            request.overrides.push_back(granflow::parse_override(value));
          }
        else if (a == "--output")
          {
            if (!request.output_directory.empty())
              throw granflow::InputError("--output " + args[i + 1] + ": --output is given twice " +
                                         "(also " + request.output_directory +
                                         "): expected one output directory per run");
            request.output_directory = args[++i];
            if (request.output_directory.empty())
              throw granflow::InputError("--output: empty directory name: expected a path");
          }
        else if (a == "--quiet")
          request.quiet = true;
        else if (a == "--help" || a == "-h")
          {
            print_usage(std::cout);
            return 0;
          }
        else if (a.rfind("--", 0) == 0)
          throw granflow::InputError("unknown option '" + a + "' (see granflow --help)");
        else if (request.case_file.empty())
          request.case_file = a;
        else
          throw granflow::InputError("unexpected argument '" + a + "': one case file per run");
      }
    if (request.case_file.empty())
      throw granflow::InputError("run: missing CASE.prm (see granflow --help)");
    // One value per entry, as in a case file (which refuses an entry set twice); compared as the
    // entry they set, whose names are trimmed ("Solver / Tolerance" is Solver/Tolerance).
    for (std::size_t i = 0; i < request.overrides.size(); ++i)
      for (std::size_t j = 0; j < i; ++j)
        if (granflow::split_list(request.overrides[j].path, '/') ==
            granflow::split_list(request.overrides[i].path, '/'))
          throw granflow::InputError("--set " + request.overrides[i].path + "=" +
                                     request.overrides[i].value + ": " + request.overrides[i].path +
                                     " is set twice (also = " + request.overrides[j].value +
                                     "): expected each entry at most once");
    granflow::interrupt::install();
    const auto summary = granflow::run_case(request);
    const std::string dir = summary.value("output_directory", std::string());
    if (request.quiet)
      {
        std::cout << "Results in " << dir << '\n';
        return 0;
      }
    std::cout << "\nDone. Results in " << dir << ":\n";
    if (std::filesystem::exists(std::filesystem::path(dir) / "solution.pvd"))
      std::cout << "  " << dir << "/solution.pvd       open with: paraview " << dir
                << "/solution.pvd\n";
    std::cout << "  " << dir << "/summary.json       key results\n";
    // only the profiles the run wrote (none where the profile line misses the material)
    std::set<std::string> profiles;
    std::error_code       ec;
    for (std::filesystem::directory_iterator f(std::filesystem::path(dir) / "profiles", ec), end;
         !ec && f != end; f.increment(ec))
      if (f->path().extension() == ".csv")
        profiles.insert(f->path().filename().string());
    if (!profiles.empty())
      std::cout << "  " << dir << "/profiles/*.csv     plot with: scripts/plot " << dir
                << "/profiles/"
                << (profiles.count("velocity.csv") ? "velocity.csv" : *profiles.begin()) << '\n';
    std::cout << "  " << dir << "/log.txt            iteration tables\n";
    return 0;
  }
} // namespace

int
main(int argc, char **argv)
{
  const std::vector<std::string> args(argv + 1, argv + argc);
  if (args.empty())
    {
      std::cerr << "granflow: error: missing command: expected run, print-parameters, "
                   "list-cases, --help or --version (`granflow --help` shows how)\n";
      return granflow::exit_status::bad_input;
    }
  if (args[0] == "--help" || args[0] == "-h" || args[0] == "help")
    {
      print_usage(std::cout);
      return 0;
    }
  if (args[0] == "--version" && args.size() == 1)
    {
      std::cout << "granflow " << GRANFLOW_VERSION << '\n';
      return 0;
    }
  try
    {
      if (args.size() == 2 && (args[1] == "--help" || args[1] == "-h"))
        {
          print_usage(std::cout); // for every command, as for run's options
          return 0;
        }
      if (args[0] == "run")
        return run({args.begin() + 1, args.end()});
      if (args[0] == "--version")
        throw granflow::InputError("--version: unexpected argument '" + args[1] +
                                   "': it takes none");
      if (args[0] == "list-cases")
        {
          if (args.size() != 1)
            throw granflow::InputError("list-cases: unexpected argument '" + args[1] +
                                       "': it takes none");
          return list_cases();
        }
      if (args[0] == "print-parameters")
        {
          if (args.size() != 2)
            throw granflow::InputError("print-parameters: expected one MODEL (e.g. dp)");
          return print_parameters(args[1]);
        }
      throw granflow::InputError("unknown command '" + args[0] + "' (see granflow --help)");
    }
  catch (const granflow::InputError &e)
    {
      std::cerr << "granflow: error: " << e.what() << '\n';
      return granflow::exit_status::bad_input;
    }
  catch (const granflow::Interrupted &e)
    {
      std::cerr << granflow::ending_line(e) << '\n';
      return e.exit_status();
    }
  catch (const granflow::ConvergenceError &e)
    {
      std::cerr << granflow::ending_line(e) << '\n';
      return granflow::exit_status::not_converged;
    }
  catch (const std::exception &e)
    {
      std::cerr << "granflow: internal error: " << e.what() << '\n';
      return granflow::exit_status::internal_error;
    }
}
