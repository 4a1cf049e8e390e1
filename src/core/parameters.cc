#include "core/parameters.h"

#include "core/errors.h"

#include <deal.II/base/exceptions.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iterator>
#include <map>
#include <regex>
#include <sstream>
#include <stdexcept>

namespace granflow
{
  std::string
  trim(const std::string &s)
  {
    const auto b = s.find_first_not_of(" \t\n\r");
    if (b == std::string::npos)
      return "";
    const auto e = s.find_last_not_of(" \t\n\r");
    return s.substr(b, e - b + 1);
  }

  namespace
  {

    /// deal.II's messages span several lines; a user gets them on one.
    std::string
    one_line(const dealii::ExceptionBase &e)
    {
      std::ostringstream info;
      e.print_info(info);
      std::string       out;
      bool              space = false;
      for (const char c : info.str())
        {
          if (std::isspace(static_cast<unsigned char>(c)))
            space = !out.empty();
          else
            {
              if (space)
                out += ' ';
              out += c;
              space = false;
            }
        }
      return out;
    }

    /// A deal.II pattern description in words: "[Double 0...MAX_DOUBLE (inclusive)]" -> "a number
    /// in [0, inf)", "[Selection a|b ]" -> "one of 'a', 'b'", "[Double > 0]" -> "a number > 0".
    std::string
    describe_pattern(std::string p)
    {
      std::smatch m;
      const auto  bound = [](const std::string &b) {
        return b == "MAX_DOUBLE" || b == "2147483647" ? std::string("inf") : b;
      };
      const auto lower = [](const std::string &b) {
        return b == "-MAX_DOUBLE" || b == "-2147483648" ? std::string("-inf") : b;
      };
      if (std::regex_match(p, m, std::regex(R"(\[?Double (.*)\.\.\.(.*) \(inclusive\)\]?)")))
        return "a number in [" + lower(m[1]) + ", " + bound(m[2]) +
               (bound(m[2]) == "inf" ? ")" : "]");
      if (std::regex_match(p, m, std::regex(R"(\[?Integer range (.*)\.\.\.(.*) \(inclusive\)\]?)")))
        return "an integer in [" + lower(m[1]) + ", " + bound(m[2]) +
               (bound(m[2]) == "inf" ? ")" : "]");
      if (std::regex_match(p, m, std::regex(R"(\[?Double (.*?)\]?)")))
        return "a number " + std::string(m[1]);
      if (std::regex_match(p, m, std::regex(R"(\[?Selection (.*?) *\]?)")))
        {
          std::string out;
          for (const auto &choice : split_list(m[1], '|'))
            out += (out.empty() ? "one of '" : ", '") + choice + "'";
          return out;
        }
      if (std::regex_match(p, std::regex(R"(\[?Bool\]?)")))
        return "true or false";
      return p;
    }

    /// Calls f(key) with `prm` inside the subsections of the entry path {"Section", ..., "key"}.
    template <typename F>
    void
    at_entry(dealii::ParameterHandler &prm, const std::vector<std::string> &path, const F &f)
    {
      std::size_t entered = 0;
      const auto  leave   = [&] {
        for (; entered > 0; --entered)
          prm.leave_subsection();
      };
      try
        {
          for (; entered + 1 < path.size(); ++entered)
            prm.enter_subsection(path[entered]);
          f(path.back());
        }
      catch (...)
        {
          leave(); // the caller's error message reads the top level
          throw;
        }
      leave();
    }

    /// deal.II's "value does not match the pattern" messages, said as the project says them.
    std::string
    readable(const std::string &message)
    {
      std::smatch m;
      if (std::regex_search(
              message, m,
              std::regex(R"(The string <(.*)> does not match the given pattern <(.*)>\.?$)")))
        return "value '" + std::string(m[1]) + "' is invalid: expected " + describe_pattern(m[2]);
      if (std::regex_search(
              message, m,
              std::regex(
                  R"(Line <(\d+)> of file <[^>]*>: The entry value (.*) for the entry named (.*) does not match the given pattern:? <?(\[.*\])>?\.?$)")))
        return "line " + std::string(m[1]) + ": entry '" + std::string(m[3]) + "': value '" +
               std::string(m[2]) + "' is invalid: expected " + describe_pattern(m[4]);
      if (std::regex_search(
              message, m,
              std::regex(
                  R"(Line <(\d+)> of file <[^>]*>: No entry with name <(.*)> was declared in the current subsection)")))
        return "line " + std::string(m[1]) + ": unknown entry '" + std::string(m[2]) +
               "' in its subsection";
      if (std::regex_search(
              message, m,
              std::regex(
                  R"(Line <(\d+)> of file <.*There is no such subsection to be entered: (.*)$)")))
        {
          std::string path = m[2]; // deal.II joins the path with '.', the project with '/'
          std::replace(path.begin(), path.end(), '.', '/');
          return "line " + std::string(m[1]) + ": unknown subsection '" + path + "'";
        }
      return message;
    }

    /// Where to look up the entries of the case file's model.
    std::string
    entries_hint(const dealii::ParameterHandler &prm)
    {
      const std::string model = trim(prm.get("Model"));
      return " (`granflow print-parameters " + (model.empty() ? std::string("MODEL") : model) +
             "` lists every entry)";
    }

    void
    require_readable(const std::string &file)
    {
      if (!std::filesystem::is_regular_file(file) || !std::ifstream(file))
        throw InputError(file + ": cannot open the case file (no such readable file)");
    }

    /// The case file's text without a UTF-8 byte-order mark, which some editors write and
    /// deal.II took for part of the first word ("The line <set Model = dp> could not be parsed",
    /// the mark invisible). A file with control characters (a binary file) is refused as not
    /// text; deal.II quoted its bytes.
    std::string
    case_text(const std::string &file)
    {
      require_readable(file);
      std::ifstream in(file, std::ios::binary);
      std::string   text{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
      if (text.rfind("\xEF\xBB\xBF", 0) == 0)
        text.erase(0, 3);
      unsigned int line = 1;
      for (const char c : text)
        {
          const auto byte = static_cast<unsigned char>(c);
          if (c == '\n')
            ++line;
          else if ((byte < 0x20 && c != '\t' && c != '\r' && c != '\f' && c != '\v') ||
                   byte == 0x7f)
            {
              std::ostringstream hex;
              hex << "0x" << std::hex << std::setw(2) << std::setfill('0') << unsigned(byte);
              throw InputError(file + ": line " + std::to_string(line) + ": byte " + hex.str() +
                               " is not text: expected a case file of 'set', 'subsection' and "
                               "'end' lines (`granflow print-parameters MODEL` writes one)");
            }
        }
      return text;
    }

    /// What ParameterHandler does not say, with the line: a subsection left open at the end of the
    /// file (deal.II's message has no line), and an entry set twice (deal.II keeps the last value
    /// without a word, so a user's edit above a forgotten line had no effect).
    void
    check_structure(const std::string &file, const std::string &text)
    {
      std::istringstream                            in(text);
      std::vector<std::pair<std::string, unsigned>> open;   // subsection name, line
      std::map<std::string, unsigned>               set_on; // "Section/key" -> line
      std::string                                   line, logical;
      unsigned                                      number = 0, first = 0;
      const auto words = [](const std::string &text) { // trimmed, inner blanks collapsed
        std::istringstream w(text);
        std::string        word, joined;
        while (w >> word)
          joined += (joined.empty() ? "" : " ") + word;
        return joined;
      };
      // deal.II's keywords, in lower or upper case (ParameterHandler::scan_line)
      const auto starts = [](const std::string &text, const std::string &keyword) {
        std::string upper = keyword;
        std::transform(upper.begin(), upper.end(), upper.begin(), ::toupper);
        return text.rfind(keyword, 0) == 0 || text.rfind(upper, 0) == 0;
      };
      while (std::getline(in, line))
        {
          ++number;
          if (logical.empty())
            first = number;
          // A trailing backslash continues the line, even a comment (ParameterHandler joins the
          // lines first and strips comments after).
          line.erase(line.find_last_not_of(" \t\r") + 1);
          if (!line.empty() && line.back() == '\\')
            {
              logical += line.substr(0, line.size() - 1) + " ";
              continue;
            }
          line = logical + line;
          logical.clear();
          if (const auto hash = line.find('#'); hash != std::string::npos)
            line.erase(hash);
          line = words(line);
          if (starts(line, "subsection "))
            open.emplace_back(words(line.substr(11)), first);
          else if (starts(line, "end"))
            {
              // text after "end" is deal.II's to report, with its line
              if (!open.empty())
                open.pop_back();
            }
          else if (starts(line, "set "))
            {
              std::string path;
              for (const auto &section : open)
                path += section.first + "/";
              path += words(line.substr(4, line.find('=') - 4));
              if (const auto [it, fresh] = set_on.emplace(path, first); !fresh)
                throw InputError(file, path,
                                 "is set on line " + std::to_string(it->second) +
                                     " and again on line " + std::to_string(first) +
                                     ": expected one value (delete one of the lines)");
            }
          // (an included file's entries are not followed)
        }
      if (!open.empty())
        throw InputError(file + ": subsection '" + open.back().first + "' opened on line " +
                         std::to_string(open.back().second) +
                         " is not closed: expected an 'end' line for it");
    }
  } // namespace

  Interval::Interval(const double lower, const bool lower_open, const double upper,
                     const bool upper_open)
      : lower(lower)
      , upper(upper)
      , lower_open(lower_open)
      , upper_open(upper_open)
  {
  }

  bool
  Interval::match(const std::string &test) const
  {
    std::istringstream in(test);
    double             x;
    in >> x;
    if (in.fail())
      return false;
    std::string rest;
    in >> rest; // nothing may follow the number
    if (!rest.empty() || !std::isfinite(x))
      return false;
    return (lower_open ? x > lower : x >= lower) && (upper_open ? x < upper : x <= upper);
  }

  std::string
  Interval::description(const OutputStyle) const
  {
    std::ostringstream s;
    if (upper == inf)
      s << "[Double " << (lower_open ? "> " : ">= ") << lower << "]";
    else
      s << "[Double in " << (lower_open ? '(' : '[') << lower << ", " << upper
        << (upper_open ? ')' : ']') << "]";
    return s.str();
  }

  std::unique_ptr<dealii::Patterns::PatternBase>
  Interval::clone() const
  {
    return std::make_unique<Interval>(*this);
  }

  Override
  parse_override(const std::string &argument)
  {
    const auto eq = argument.find('=');
    if (eq == std::string::npos || eq == 0)
      throw InputError("--set " + argument + ": expected Section/key=value");
    return {trim(argument.substr(0, eq)), trim(argument.substr(eq + 1))};
  }

  std::string
  read_model_name(const std::string &case_file)
  {
    const std::string text = case_text(case_file);
    check_structure(case_file, text);
    dealii::ParameterHandler prm;
    prm.declare_entry("Model", "", dealii::Patterns::Anything(), "");
    try
      {
        std::istringstream in(text);
        prm.parse_input(in, case_file, "", true);
      }
    catch (const dealii::ExceptionBase &e)
      {
        throw InputError(case_file + ": " + readable(one_line(e)));
      }
    const std::string model = trim(prm.get("Model"));
    if (model.empty())
      throw InputError(case_file, "Model", "missing: the case file must say 'set Model = dp' (see "
                                           "`granflow print-parameters dp`)");
    return model;
  }

  void
  parse_case_file(dealii::ParameterHandler &prm, const std::string &case_file,
                  const std::vector<Override>    &overrides,
                  const std::vector<std::string> &path_entries)
  {
    const std::string text = case_text(case_file);
    check_structure(case_file, text);
    try
      {
        std::istringstream in(text); // the text format whatever the file's extension
        prm.parse_input(in, case_file);
      }
    catch (const dealii::ExceptionBase &e)
      {
        const std::string message = readable(one_line(e));
        const bool        unknown = message.find(": unknown ") != std::string::npos;
        throw InputError(case_file + ": " + message +
                         (unknown ? entries_hint(prm) : std::string()));
      }
    const std::filesystem::path case_directory = std::filesystem::path(case_file).parent_path();
    for (const std::string &entry : path_entries)
      {
        at_entry(prm, split_list(entry, '/'), [&](const std::string &key) {
          const std::filesystem::path value = prm.get(key);
          // absolute, so that the parameters.prm a run writes can be rerun from anywhere
          if (!value.empty() && value.is_relative())
            prm.set(key,
                    std::filesystem::absolute(case_directory / value).lexically_normal().string());
        });
      }
    for (const Override &o : overrides)
      {
        const std::vector<std::string> path = split_list(o.path, '/');
        if (path.empty())
          throw InputError("--set " + o.path + "=" + o.value + ": empty entry name");
        try
          {
            at_entry(prm, path, [&](const std::string &key) { prm.set(key, o.value); });
          }
        catch (const dealii::ExceptionBase &e)
          {
            const std::string message = one_line(e);
            if (message.find("you have not yet declared") != std::string::npos)
              throw InputError("--set " + o.path + "=" + o.value + ": unknown entry '" + o.path +
                               "'" + entries_hint(prm));
            throw InputError("--set " + o.path + "=" + o.value + ": " + readable(message));
          }
      }
  }

  void
  rethrow_naming_overrides(const InputError &e, const std::string &case_file,
                           const std::vector<Override> &overrides)
  {
    if (e.entry().empty() || overrides.empty())
      throw e;
    for (auto o = overrides.rbegin(); o != overrides.rend(); ++o)
      if (split_list(o->path, '/') == split_list(e.entry(), '/'))
        throw InputError("--set " + o->path + "=" + o->value, e.entry(), e.detail());
    // An entry of the case file judged with values from the command line (the Bingham reference
    // refused for --set 'Boundary conditions/Zero y-velocity='): the overrides of the entries the
    // message names are named beside the file.
    const std::string prefix = case_file + ": entry '";
    if (std::string(e.what()).rfind(prefix, 0) != 0)
      throw e;
    std::string with;
    for (const auto &o : overrides)
      if (const auto names = split_list(o.path, '/');
          !names.empty() && e.detail().find(names.back()) != std::string::npos)
        with += (with.empty() ? " with --set " : ", --set ") + o.path + "=" + o.value;
    if (!with.empty())
      throw InputError(case_file + with, e.entry(), e.detail());
    // A check may read an entry without naming it, so which override mattered is not known: the
    // file is named with every override the run had, as context rather than blame.
    std::string all;
    for (const auto &o : overrides)
      all += (all.empty() ? " (run with --set " : ", --set ") + o.path + "=" + o.value;
    throw InputError(case_file + all + ")", e.entry(), e.detail());
  }

  std::vector<std::string>
  split_list(const std::string &list, const char separator)
  {
    std::vector<std::string> items;
    std::stringstream        in(list);
    std::string              item;
    while (std::getline(in, item, separator))
      if (!trim(item).empty())
        items.push_back(trim(item));
    return items;
  }

  void
  check_list_items(const std::string &list, const std::string &file, const std::string &entry)
  {
    if (trim(list).empty())
      return;
    std::stringstream in(list + ","); // getline drops a last empty item: the comma keeps it
    std::string       item;
    while (std::getline(in, item, ','))
      if (trim(item).empty())
        throw InputError(file, entry,
                         "'" + trim(list) +
                             "' has an empty item: expected items separated by single commas");
  }

  double
  parse_number(const std::string &text)
  {
    std::size_t used  = 0;
    double      value = 0.;
    try
      {
        value = std::stod(text, &used); // throws invalid_argument for no number
      }
    catch (const std::out_of_range &) // 1e400, and 1e-400, whose underflow stod also refuses
      {
        throw std::invalid_argument("out of the range of a double: '" + text + "'");
      }
    if (!trim(text.substr(used)).empty() || !std::isfinite(value))
      throw std::invalid_argument("not a finite number: '" + text + "'");
    return value;
  }

  std::vector<std::pair<std::string, double>>
  parse_named_values(const std::string &list, const std::string &file, const std::string &entry)
  {
    check_list_items(list, file, entry);
    std::vector<std::pair<std::string, double>> result;
    for (const std::string &item : split_list(list))
      {
        const auto colon = item.find(':');
        try
          {
            if (colon == std::string::npos)
              throw std::invalid_argument("");
            result.emplace_back(trim(item.substr(0, colon)), parse_number(item.substr(colon + 1)));
          }
        catch (const std::exception &)
          {
            throw InputError(file, entry,
                             "cannot read '" + item +
                                 "': expected 'boundary: number' (a finite number)");
          }
        require_last_name_new(result, file, entry);
      }
    return result;
  }
} // namespace granflow
