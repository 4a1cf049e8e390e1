// Case files: deal.II ParameterHandler files in which every entry has a default, a range (pattern)
// and a help text. Reading a case turns every deal.II parse error into one InputError that names
// the file, the entry and the expected range. Only core/ and apps/ read files (DESIGN.md).
#pragma once

#include "core/errors.h"

#include <deal.II/base/parameter_handler.h>

#include <algorithm>
#include <filesystem>
#include <limits>
#include <memory>
#include <string>
#include <utility>
#include <vector>

namespace granflow
{
  /// A real number in an interval whose ends may be open: the pattern of entries such as "> 0" or
  /// "(0, 1e6]". deal.II's Patterns::Double includes both ends, so an entry that must be positive
  /// showed the range [0, MAX_DOUBLE] and was then rejected at 0 by a second check.
  class Interval : public dealii::Patterns::PatternBase
  {
  public:
    static constexpr double inf = std::numeric_limits<double>::infinity();
    Interval(double lower, bool lower_open, double upper = inf, bool upper_open = true);
    /// (0, inf): a positive number.
    static Interval
    positive(double upper = inf)
    {
      return {0., true, upper, upper == inf};
    }
    bool
    match(const std::string &test) const override;
    std::string
    description(OutputStyle style = Machine) const override;
    std::unique_ptr<dealii::Patterns::PatternBase>
    clone() const override;

  private:
    double lower, upper;
    bool   lower_open, upper_open;
  };

  /// A `--set Section/key=value` override from the command line.
  struct Override
  {
    std::string path; // "Section/Subsection/key"
    std::string value;
  };

  /// Parses "Section/key=value"; throws InputError on a malformed argument.
  Override
  parse_override(const std::string &argument);

  /// Reads the top-level entry `Model` of a case file without knowing the model's entries.
  std::string
  read_model_name(const std::string &case_file);

  /// Parses `case_file` into `prm` (whose entries are already declared), then applies the
  /// overrides. Unknown entries, values outside their range and unreadable files end in InputError.
  /// `path_entries` ("Section/key") hold file names: a relative one written in the case file is
  /// taken relative to the case file's directory (the case and its mesh travel together); one given
  /// with --set stays relative to the current directory, as on any command line.
  void
  parse_case_file(dealii::ParameterHandler &prm, const std::string &case_file,
                  const std::vector<Override>    &overrides,
                  const std::vector<std::string> &path_entries = {});

  /// Re-throws `e`; if it is about an entry that an override set, it names that
  /// `--set Section/key=value` instead of the case file, which does not hold the value; if it is
  /// about another entry of `case_file` whose message names entries that overrides set, it names
  /// the file "with --set ..." those overrides, for the error may come from their values; about
  /// another entry of `case_file` otherwise, it names the file "(run with --set ...)" every
  /// override, since a check may read an entry its message does not name.
  [[noreturn]] void
  rethrow_naming_overrides(const InputError &e, const std::string &case_file,
                           const std::vector<Override> &overrides);

  /// `s` without leading and trailing blanks (spaces, tabs, line ends).
  std::string
  trim(const std::string &s);

  /// Declares the entries of a model's Parameters in `prm` (declare(prm)), parses `case_file` with
  /// the overrides and validates (validate()); InputError on bad input.
  template <typename ModelParameters>
  void
  read_case(ModelParameters &parameters, dealii::ParameterHandler &prm,
            const std::string &case_file, const std::vector<Override> &overrides)
  {
    parameters.declare(prm);
    parse_case_file(prm, case_file, overrides, ModelParameters::path_entries());
    // Every model has a top-level Name: by default the case file's name, as the default output
    // directory is. Set in prm, so that the parameters.prm a run writes keeps it; a '#' would
    // start a comment there and a trailing backslash continue the line.
    if (trim(prm.get("Name")).empty())
      {
        std::string name = std::filesystem::path(case_file).stem().string();
        std::replace(name.begin(), name.end(), '#', '_');
        std::replace(name.begin(), name.end(), '\\', '_');
        prm.set("Name", name);
      }
    parameters.case_file = case_file;
    parameters.validate();
  }

  /// read_case() into a fresh ParameterHandler.
  template <typename ModelParameters>
  ModelParameters
  load_case(const std::string &case_file, const std::vector<Override> &overrides)
  {
    ModelParameters          parameters;
    dealii::ParameterHandler prm;
    read_case(parameters, prm, case_file, overrides);
    return parameters;
  }

  /// Splits "a, b, c" into trimmed non-empty items.
  std::vector<std::string>
  split_list(const std::string &list, char separator = ',');

  /// Refuses a comma-separated list with an empty item ("wall,,bottom", "wall,"): a typo that
  /// split_list() would pass over. An empty list is none. Throws InputError naming file and entry.
  void
  check_list_items(const std::string &list, const std::string &file, const std::string &entry);

  /// The finite number that is the whole of `text` (spaces around it aside); throws
  /// std::invalid_argument for anything else ("1abc", "", "nan", "1e400", and "1e-400", which
  /// underflows).
  double
  parse_number(const std::string &text);

  /// Refuses a list of (name, value) items whose last name occurs earlier in it: each boundary
  /// of a "name: value, ..." entry at most once. Throws InputError naming file and entry.
  template <typename Value>
  void
  require_last_name_new(const std::vector<std::pair<std::string, Value>> &named,
                        const std::string &file, const std::string &entry)
  {
    for (std::size_t i = 0; i + 1 < named.size(); ++i)
      if (named[i].first == named.back().first)
        throw InputError(file, entry,
                         "names boundary '" + named.back().first +
                             "' a second time: expected each boundary at most once");
  }

  /// Parses "name: value, name: value" into pairs; throws InputError naming file and entry.
  std::vector<std::pair<std::string, double>>
  parse_named_values(const std::string &list, const std::string &file, const std::string &entry);
} // namespace granflow
