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

    std::string
    upper_case(std::string text)
    {
      std::transform(text.begin(), text.end(), text.begin(), ::toupper);
      return text;
    }

    std::string
    lower_case(std::string text)
    {
      std::transform(text.begin(), text.end(), text.begin(), ::tolower);
      return text;
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
                  R"(Line <(\d+)> of file <[^>]*>: Invalid format of 'set' or 'SET' statement)")))
        return "line " + std::string(m[1]) +
               ": a 'set' line without '=': expected 'set key = value'";
      if (std::regex_search(
              message, m,
              std::regex(R"(Line <(\d+)> of file <[^>]*>: The line <(.*)> could not be parsed)")))
        {
          const std::string line  = m[2];
          const auto        equal = line.find('=');
          std::string       first_word;
          std::istringstream(line) >> first_word;
          const std::string lower = lower_case(first_word);
          const bool        keyword =
              lower == "set" || lower == "subsection" || lower == "end" || lower == "include";
          // (a keyword in mixed case, 'Set': deal.II knows only 'set' and 'SET')
          const std::string expected =
              keyword ? "'" + lower + "' or '" + upper_case(lower) + "', not '" + first_word + "'"
              : equal != std::string::npos && !trim(line.substr(0, equal)).empty()
                  ? "'set " + line + "'"
                  : std::string("one of four forms");
          return "line " + std::string(m[1]) + ": '" + line +
                 "' is not a case-file line: expected " + expected +
                 " (each line sets an entry, opens or ends a subsection, or is a comment: 'set key "
                 "= value', 'subsection Name', 'end', '# ...')";
        }
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
      std::error_code error; // (a name too long for the system is no such file)
      if (!std::filesystem::is_regular_file(file, error) || !std::ifstream(file))
        throw InputError(file + ": cannot open the case file (" +
                         (std::filesystem::is_directory(file, error) ? "it is a directory"
                                                                     : "no such readable file") +
                         "): expected a case file such as cases/daviet2016/cylinder.prm "
                         "(`granflow list-cases` lists them)");
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

    /// deal.II's keywords, in lower or upper case (ParameterHandler::scan_line).
    bool
    starts_with_keyword(const std::string &text, const std::string &keyword)
    {
      return text.rfind(keyword, 0) == 0 || text.rfind(upper_case(keyword), 0) == 0;
    }

    /// Trimmed, inner blanks collapsed.
    std::string
    words(const std::string &text)
    {
      std::istringstream w(text);
      std::string        word, joined;
      while (w >> word)
        joined += (joined.empty() ? "" : " ") + word;
      return joined;
    }

    /// A subsection open at some line of a case file: its name and the line that opened it.
    using OpenSections = std::vector<std::pair<std::string, unsigned int>>;

    /// Reads a case file's text as ParameterHandler does and calls visit(first, line, open) for
    /// each logical line. `first` is its first physical line: a trailing backslash continues a
    /// line, even a comment (ParameterHandler trims the lines, joins them without a blank and
    /// strips comments after). `line` is without its comment, trimmed, with its blanks collapsed;
    /// `open` are the subsections open before it. Returns those left open at the end.
    template <typename Visit>
    OpenSections
    scan_case_text(const std::string &text, const Visit &visit)
    {
      std::istringstream in(text);
      OpenSections       open;
      std::string        line, logical;
      unsigned int       number = 0, first = 0;
      while (std::getline(in, line))
        {
          ++number;
          if (logical.empty())
            first = number;
          line = trim(line); // ParameterHandler trims every physical line, then joins them
          if (!line.empty() && line.back() == '\\')
            {
              logical += line.substr(0, line.size() - 1);
              continue;
            }
          line = logical + line;
          logical.clear();
          if (const auto hash = line.find('#'); hash != std::string::npos)
            line.erase(hash);
          line = words(line);
          visit(first, line, static_cast<const OpenSections &>(open));
          if (starts_with_keyword(line, "subsection "))
            open.emplace_back(words(line.substr(11)), first);
          else if (starts_with_keyword(line, "end") && !open.empty())
            open.pop_back(); // text after "end" is deal.II's to report, with its line
          // (an included file's entries are not followed)
        }
      return open;
    }

    /// "Section/Sub/" for the subsections `open` ("" at the top level).
    std::string
    section_path(const OpenSections &open)
    {
      std::string path;
      for (const auto &section : open)
        path += section.first + "/";
      return path;
    }

    /// What ParameterHandler does not say, with the line: a subsection left open at the end of the
    /// file (deal.II's message has no line), and an entry set twice (deal.II keeps the last value
    /// without a word, so a user's edit above a forgotten line had no effect).
    void
    check_structure(const std::string &file, const std::string &text)
    {
      std::map<std::string, unsigned int> set_on; // "Section/key" -> line
      const auto check_line = [&](const unsigned int first, const std::string &line,
                                  const OpenSections &open) {
        if (!starts_with_keyword(line, "set "))
          return;
        const std::string path = section_path(open) + words(line.substr(4, line.find('=') - 4));
        if (const auto [it, fresh] = set_on.emplace(path, first); !fresh)
          throw InputError(file, path,
                           "is set on line " + std::to_string(it->second) + " and again on line " +
                               std::to_string(first) +
                               ": expected one value (delete one of the lines)");
      };
      const OpenSections open = scan_case_text(text, check_line);
      if (!open.empty())
        throw InputError(file + ": subsection '" + open.back().first + "' opened on line " +
                         std::to_string(open.back().second) +
                         " is not closed: expected an 'end' line for it");
    }

    /// The subsections open at line `number` of a case file's text ("Section/Sub/", "" at the
    /// top level).
    std::string
    section_at_line(const std::string &text, const unsigned int number)
    {
      std::string path;
      scan_case_text(text,
                     [&](const unsigned int first, const std::string &, const OpenSections &open) {
                       if (first == number)
                         path = section_path(open);
                     });
      return path;
    }

    /// Every declared entry and subsection of `prm` as "Section/key" and "Section/Sub/" (a
    /// subsection ends with '/'), read back from its own case-file form.
    std::vector<std::string>
    declared_names(const dealii::ParameterHandler &prm)
    {
      std::ostringstream form;
      prm.print_parameters(form, dealii::ParameterHandler::ShortPRM);
      std::vector<std::string> names;
      scan_case_text(
          form.str(), [&](const unsigned int, const std::string &line, const OpenSections &open) {
            if (starts_with_keyword(line, "set "))
              names.push_back(section_path(open) + words(line.substr(4, line.find('=') - 4)));
            else if (starts_with_keyword(line, "subsection "))
              names.push_back(section_path(open) + words(line.substr(11)) + "/");
          });
      return names;
    }

    /// Edit distance of a and b, letters compared without case (a wrong case costs 1 / 4).
    double
    edit_distance(const std::string &a, const std::string &b)
    {
      std::vector<double> row(b.size() + 1);
      for (std::size_t j = 0; j <= b.size(); ++j)
        row[j] = static_cast<double>(j);
      for (std::size_t i = 1; i <= a.size(); ++i)
        {
          double diagonal = row[0];
          row[0]          = static_cast<double>(i);
          for (std::size_t j = 1; j <= b.size(); ++j)
            {
              const char   x = a[i - 1], y = b[j - 1];
              const double change = x == y ? 0.
                                           : (std::tolower(static_cast<unsigned char>(x)) ==
                                                      std::tolower(static_cast<unsigned char>(y))
                                                  ? 0.25
                                                  : 1.);
              const double next   = std::min({row[j] + 1., row[j - 1] + 1., diagonal + change});
              diagonal            = row[j];
              row[j]              = next;
            }
        }
      return row[b.size()];
    }

    /// " (did you mean 'x'?)" for the declared names in `section` ("Section/", "" at the top level)
    /// nearest to `name`, entries or (subsection = true) subsections, if within a third of the
    /// name's length (at least 0.5: a short name matches only in another case); else, if `name`
    /// is declared elsewhere, where (and, in a case file, whether an 'end' is missing).
    std::string
    suggestion(const dealii::ParameterHandler &prm, const std::string &section,
               const std::string &name, const bool subsection, const bool in_case_file = true)
    {
      // (section, name) of each declared entry or subsection; "" is the top level
      std::vector<std::pair<std::string, std::string>> declared;
      for (const std::string &full : declared_names(prm))
        if ((full.back() == '/') == subsection)
          {
            const std::string path  = subsection ? full.substr(0, full.size() - 1) : full;
            const auto        slash = path.rfind('/');
            declared.emplace_back(slash == std::string::npos ? "" : path.substr(0, slash + 1),
                                  path.substr(slash == std::string::npos ? 0 : slash + 1));
          }
      std::vector<std::string> best;
      double                   best_distance = std::max(0.5, static_cast<double>(name.size()) / 3.);
      for (const auto &[where, candidate] : declared)
        if (where == section)
          {
            const double d = edit_distance(name, candidate);
            if (d < best_distance)
              best.clear();
            if (d <= best_distance)
              {
                best.push_back(candidate);
                best_distance = d;
              }
          }
      // The message has its blanks collapsed; deal.II compares names as they are written.
      if (best.size() == 1 && best_distance == 0.)
        return " (write it with single blanks between its words)";
      if (!best.empty())
        {
          std::string list;
          for (std::size_t i = 0; i < best.size(); ++i)
            list += std::string(i == 0                 ? ""
                                : i + 1 == best.size() ? " or "
                                                       : ", ") +
                    "'" + best[i] + "'";
          return " (did you mean " + list + "?)";
        }
      std::string elsewhere;
      bool        outer = false; // declared in a subsection that encloses `section`
      for (const auto &[where, candidate] : declared)
        if (candidate == name && where != section)
          {
            elsewhere += (elsewhere.empty() ? "" : ", ") +
                         (where.empty() ? std::string("the top level")
                                        : "'" + where.substr(0, where.size() - 1) + "'");
            outer = outer || section.rfind(where, 0) == 0;
          }
      return elsewhere.empty()
                 ? std::string()
                 : " ('" + name + "' is " + (subsection ? "a subsection" : "an entry") + " of " +
                       elsewhere +
                       (outer && in_case_file ? "; is an 'end' missing above it?" : "") + ")";
    }

    /// readable()'s message for an unknown entry or subsection, with the subsection it is in and
    /// the declared name it is nearest to.
    std::string
    unknown_name_message(const std::string &message, const std::string &text,
                         const dealii::ParameterHandler &prm)
    {
      std::smatch m;
      if (std::regex_search(message, m,
                            std::regex(R"(^line (\d+): unknown entry '(.*)' in its subsection$)")))
        {
          const std::string section = section_at_line(text, std::stoul(m[1]));
          return "line " + std::string(m[1]) + ": unknown entry '" + std::string(m[2]) + "' " +
                 (section.empty()
                      ? std::string("at the top level")
                      : "in subsection '" + section.substr(0, section.size() - 1) + "'") +
                 suggestion(prm, section, m[2], false);
        }
      if (std::regex_search(message, m, std::regex(R"(^line (\d+): unknown subsection '(.*)'$)")))
        {
          const std::string path    = m[2];
          const auto        slash   = path.rfind('/');
          const std::string section = slash == std::string::npos ? "" : path.substr(0, slash + 1);
          return message + suggestion(prm, section, path.substr(section.size()), true);
        }
      return message;
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
    // A case file cannot hold it either: the parameters.prm a run writes would rerun another case.
    if (argument.find('#', eq) != std::string::npos)
      throw InputError("--set " + argument +
                       ": a value cannot contain '#', which begins a comment in a case file (the "
                       "run's parameters.prm would not rerun it): expected a value without '#'");
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
      throw InputError(case_file, "Model",
                       "missing: the case file must name its model, e.g. 'set Model = dp' "
                       "(`granflow --help` lists the models; `granflow print-parameters MODEL` "
                       "writes a case file with every entry)");
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
        // A line of a file the case file includes is that file's: its subsections are not
        // followed here, and its name leads the message.
        const std::string raw = one_line(e);
        std::smatch       in_file;
        const bool        included =
            std::regex_search(raw, in_file, std::regex(R"(^Line <\d+> of file <([^>]*)>)")) &&
            in_file[1] != case_file;
        const std::string message =
            included ? readable(raw) : unknown_name_message(readable(raw), text, prm);
        const bool        unknown = message.find(": unknown ") != std::string::npos;
        throw InputError(
            (included ? std::string(in_file[1]) + " (included by " + case_file + ")" : case_file) +
            ": " + message + (unknown ? entries_hint(prm) : std::string()));
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
            // A file name given on the command line is relative to the working directory (the
            // case file's to its own directory, above); made absolute, so that messages and the
            // parameters.prm a run writes say where it is.
            const bool is_path =
                std::any_of(path_entries.begin(), path_entries.end(),
                            [&](const std::string &e) { return split_list(e, '/') == path; });
            const std::string value =
                is_path && !trim(o.value).empty() &&
                        std::filesystem::path(trim(o.value)).is_relative()
                    ? std::filesystem::absolute(trim(o.value)).lexically_normal().string()
                    : o.value;
            at_entry(prm, path, [&](const std::string &key) { prm.set(key, value); });
          }
        catch (const dealii::ExceptionBase &e)
          {
            const std::string message = one_line(e);
            if (message.find("you have not yet declared") != std::string::npos)
              {
                std::string section;
                for (std::size_t i = 0; i + 1 < path.size(); ++i)
                  section += path[i] + "/";
                throw InputError("--set " + o.path + "=" + o.value + ": unknown entry '" + o.path +
                                 "'" + suggestion(prm, section, path.back(), false, false) +
                                 entries_hint(prm));
              }
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
    // as a scalar entry reads it (Interval): stod would also take hexadecimal, "0x10" for 16
    const std::string digits = trim(text);
    if (digits.find_first_of("xX") != std::string::npos)
      throw std::invalid_argument("not a decimal number: '" + text + "'");
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
                                 "': expected 'boundary: number' (a finite number, in decimal)");
          }
        require_last_name_new(result, file, entry);
      }
    return result;
  }
} // namespace granflow
