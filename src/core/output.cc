#include "core/output.h"

#include "core/errors.h"

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <sstream>

#include <fcntl.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

namespace granflow
{
  void
  write_file_atomically(const std::string &path, const std::function<void(std::ostream &)> &write)
  {
    const std::string tmp = path + ".tmp";
    std::string       failed, reason; // the path that could not be written, and why
    bool              created = false;
    {
      errno = 0;
      std::ofstream out(tmp, std::ios::binary);
      created = static_cast<bool>(out);
      if (!created)
        failed = tmp, reason = errno != 0 ? std::strerror(errno) : "cannot be opened";
      else
        try
          {
            write(out);
          }
        catch (...)
          {
            out.close();
            std::remove(tmp.c_str());
            throw;
          }
      out.close();
      if (failed.empty() && !out)
        failed = tmp, reason = errno != 0 ? std::strerror(errno) : "write error";
    }
    if (failed.empty() && std::rename(tmp.c_str(), path.c_str()) != 0)
      failed = path, reason = std::strerror(errno);
    if (!failed.empty())
      {
        if (created) // (not a file of that name that was there before, say a directory)
          std::remove(tmp.c_str());
        throw std::runtime_error("cannot write '" + failed + "': " + reason);
      }
  }

  namespace fs = std::filesystem;

  namespace
  {
    /// The list of the files the run in a directory wrote (commit()).
    constexpr const char *manifest_name = ".granflow-files";
    /// The staging directory inside the target, where the target's parent cannot be written.
    constexpr const char *inner_staging_name = ".granflow-staging";
    // the lock of a target whose parent cannot be written (beside it otherwise: .NAME.lock)
    constexpr const char *inner_lock_name = ".granflow-lock";

    /// An exclusive lock on `file` (created if missing), or -1 with errno: EWOULDBLOCK where
    /// another process holds it. A file that was unlinked and made anew while we waited for its
    /// lock (the holder removes it when it ends) is opened again, so two runs never hold two
    /// files of one name.
    int
    lock_file(const fs::path &file)
    {
      for (int attempt = 0; attempt < 100; ++attempt)
        {
          const int fd = ::open(file.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
          if (fd < 0)
            return -1;
          if (::flock(fd, LOCK_EX | LOCK_NB) != 0)
            {
              const int error = errno;
              ::close(fd);
              errno = error;
              return -1;
            }
          struct stat held, named;
          if (::fstat(fd, &held) == 0 && ::stat(file.c_str(), &named) == 0 &&
              held.st_ino == named.st_ino && held.st_dev == named.st_dev)
            return fd;
          ::close(fd);
        }
      errno = EAGAIN;
      return -1;
    }

    fs::path
    normalised(const std::string &path)
    {
      fs::path p = fs::path(path).lexically_normal();
      return p.filename().empty() ? p.parent_path() : p;
    }

    /// Files a run writes (DESIGN.md "Output directory"), relative to the output directory. On
    /// commit, those a previous run wrote (its manifest) and this run did not are removed, so
    /// that the directory never mixes two runs (e.g. an old solution.pvd beside a run without VTU
    /// output).
    bool
    is_run_output(const fs::path &relative)
    {
      const std::string name   = relative.filename().string(),
                        parent = relative.parent_path().string();
      if (parent == "profiles")
        return relative.extension() == ".csv";
      if (!parent.empty())
        return false;
      for (const char *fixed : {"solution.pvd", "summary.json", "log.txt", "parameters.prm",
                                "mesh.msh", "history.csv", "newton.csv"})
        if (name == fixed)
          return true;
      return name.rfind("solution-", 0) == 0 && relative.extension() == ".vtu";
    }
    void
    write_atomically(const fs::path &path, const std::string &content)
    {
      write_file_atomically(path.string(), [&](std::ostream &out) { out << content; });
    }

    /// `path` made absolute and canonical as far as it exists; empty if that fails.
    fs::path
    resolved(const fs::path &path)
    {
      std::error_code ec;
      // absolute first: a path not yet made has no existing prefix to make it absolute
      const fs::path result = fs::weakly_canonical(fs::absolute(path), ec);
      return ec ? fs::path() : result;
    }

    /// `path` relative to `dir` if it is `dir` or inside it (both canonical), else empty.
    fs::path
    within(const fs::path &path, const fs::path &dir)
    {
      if (path.empty() || dir.empty())
        return {};
      const fs::path relative = path.lexically_relative(dir);
      return relative.empty() || *relative.begin() == ".." ? fs::path() : relative;
    }

    /// Renames `from` to `to`, or copies it where the two are on different mounts (a bind mount
    /// of the same file system too, which st_dev does not tell apart).
    void
    move(const fs::path &from, const fs::path &to)
    {
      std::error_code ec;
      fs::rename(from, to, ec);
      if (ec == std::errc::cross_device_link)
        {
          fs::copy_file(from, to, fs::copy_options::overwrite_existing);
          fs::remove(from);
        }
      else if (ec)
        throw fs::filesystem_error("cannot move", from, to, ec);
    }
  } // namespace

  OutputDirectory::OutputDirectory(const std::string &path)
      : final_path(normalised(path).string())
      , root((normalised(path).parent_path() /
              ("." + normalised(path).filename().string() + ".staging"))
                 .string())
  {
    std::error_code ec;
    if (fs::exists(final_path, ec) && !fs::is_directory(final_path, ec))
      throw InputError("--output " + path +
                       ": exists and is not a directory: expected a directory "
                       "or a new path");
    const auto make = [&ec](const fs::path &staging) {
      ec.clear();
      fs::remove_all(staging, ec);
      fs::create_directories(staging / "profiles", ec);
      return !ec;
    };
    // Beside the target, so that a new target appears only when a run commits; inside an
    // existing target that is on another file system than its parent (a volume mounted in a
    // container: renames across the two fail) or whose parent cannot be written.
    const auto device = [](const fs::path &p) {
      struct stat status;
      return ::stat(p.c_str(), &status) == 0 ? static_cast<long long>(status.st_dev) : -1LL;
    };
    std::error_code status_ec;
    const bool      existing = fs::is_directory(final_path, status_ec);
    // One run at a time into a target: a second one removed the first's staging directory, and
    // their files mixed (two sweeps into the default results/NAME). The lock lives while this
    // object does, beside the target or, where its parent cannot be written, inside it.
    {
      const fs::path parent = normalised(path).parent_path();
      fs::create_directories(parent, ec);
      lock.path = (parent / ("." + normalised(path).filename().string() + ".lock")).string();
      lock.fd   = lock_file(lock.path);
      if (lock.fd < 0 && errno != EWOULDBLOCK && existing)
        {
          lock.path = (fs::path(final_path) / inner_lock_name).string();
          lock.fd   = lock_file(lock.path);
        }
      if (lock.fd < 0 && errno == EWOULDBLOCK)
        throw InputError("--output " + path +
                         ": another granflow run is writing into it (it holds " + lock.path +
                         "): expected another output directory, or that run to end first");
      ec.clear(); // a directory no lock can be made in fails below, as the staging directory
    }
    // A run commits by moving its files into the target: an existing target (or its profiles/)
    // that this user cannot write would fail only after the whole solve.
    for (const fs::path &directory : {fs::path(final_path), fs::path(final_path) / "profiles"})
      if (existing && fs::is_directory(directory, status_ec))
        if (const int error = ::access(directory.c_str(), W_OK | X_OK) == 0 ? 0 : errno)
          throw InputError("--output " + path + ": cannot write into the existing directory " +
                           directory.string() + " (" + std::strerror(error) +
                           "): expected a directory you can write, or a new path");
    const bool      mounted =
        existing && device(final_path) != device(fs::absolute(final_path).parent_path());
    if ((mounted || !make(root)) && existing)
      {
        const std::string inside = (fs::path(final_path) / inner_staging_name).string();
        if (make(inside))
          root = inside;
      }
    if (ec)
      throw InputError("--output " + path + ": cannot create the output directory (" +
                       ec.message() + ")");
  }

  OutputDirectory::~OutputDirectory()
  {
    std::error_code ec;
    if (!committed && !kept)
      fs::remove_all(root, ec);
  }

  OutputDirectory::Lock::~Lock()
  {
    if (fd >= 0)
      {
        ::unlink(path.c_str()); // while held: see lock_file()
        ::close(fd);
      }
  }

  void
  OutputDirectory::commit()
  {
    if (committed)
      return;
    fs::create_directories(final_path);
    // The files this run wrote, listed in the manifest that it leaves beside them.
    std::vector<fs::path> written;
    for (const auto &entry : fs::recursive_directory_iterator(root))
      if (entry.is_regular_file())
        written.push_back(fs::relative(entry.path(), root));
    // The earlier run's files that this run did not write: only those its manifest lists, so
    // that a user's own files in the directory are never touched, even where their names look
    // like a run's (profiles/notes.csv, history.csv). A directory without a manifest (new, or
    // written before session 18) loses nothing; its files of the same names are replaced.
    std::vector<fs::path> stale; // relative to the target
    if (std::ifstream manifest(fs::path(final_path) / manifest_name); manifest)
      for (std::string line; std::getline(manifest, line);)
        {
          const fs::path relative = fs::path(line).lexically_normal();
          if (!line.empty() && is_run_output(relative) && !fs::exists(fs::path(root) / relative) &&
              fs::is_regular_file(fs::path(final_path) / relative))
            stale.push_back(relative);
        }
    const auto write_manifest = [this](const std::vector<fs::path> &files) {
      std::string list;
      for (const auto &file : files)
        list += file.generic_string() + '\n';
      write_atomically(fs::path(final_path) / manifest_name, list);
    };
    // Before anything moves, the manifest lists both runs' files, and after, this run's: a commit
    // that fails part-way leaves every file of either run listed for the next run to remove.
    std::vector<fs::path> both = written;
    both.insert(both.end(), stale.begin(), stale.end());
    write_manifest(both);
    // The new files first, then the earlier run's leftovers: a move that fails part-way leaves
    // the earlier run's files that it did not replace in place.
    for (const auto &entry : fs::recursive_directory_iterator(root))
      {
        const fs::path target = fs::path(final_path) / fs::relative(entry.path(), root);
        if (entry.is_directory())
          fs::create_directories(target);
        else
          {
            moving = true;
            move(entry.path(), target);
          }
      }
    for (const auto &file : stale)
      fs::remove(fs::path(final_path) / file);
    write_manifest(written);
    // a staging folder an earlier run left inside the target (keep_staging()); the name is ours
    std::error_code ec;
    if (fs::path(root) != fs::path(final_path) / inner_staging_name)
      fs::remove_all(fs::path(final_path) / inner_staging_name, ec);
    fs::remove_all(root);
    root      = final_path;
    committed = true;
  }

  bool
  OutputDirectory::would_replace(const std::string &existing) const
  {
    std::error_code ec;
    const fs::path  file = resolved(existing);
    if (!fs::is_regular_file(file, ec))
      return false;
    const fs::path relative = within(file, resolved(final_path));
    return !relative.empty() && is_run_output(relative);
  }

  std::string
  OutputDirectory::left_as_it_was() const
  {
    if (fs::path(root) == fs::path(final_path) / inner_staging_name)
      return final_path + " is as it was but for its hidden " + inner_staging_name +
             ", which holds the log of this run, " + file("log.txt");
    return final_path + " was left as it was, and the log of this run is " + file("log.txt");
  }

  bool
  OutputDirectory::in_target(const std::string &path) const
  {
    const fs::path file = resolved(fs::path(root) / path);
    // not in a staging directory inside it
    return !within(file, resolved(final_path)).empty() && within(file, resolved(root)).empty();
  }

  bool
  OutputDirectory::is_run_file(const std::string &relative)
  {
    const fs::path path = fs::path(relative).lexically_normal();
    return is_run_output(path) || path == manifest_name;
  }

  std::string
  OutputDirectory::file(const std::string &name) const
  {
    return (fs::path(root) / name).string();
  }

  void
  OutputDirectory::write_text(const std::string &name, const std::string &content) const
  {
    write_atomically(file(name), content);
  }

  void
  OutputDirectory::write_json(const std::string &name, const nlohmann::json &json) const
  {
    write_text(name, json.dump(2) + "\n");
  }

  void
  OutputDirectory::write_csv(const std::string &name, const std::vector<std::string> &header,
                             const std::vector<std::vector<double>> &columns) const
  {
    std::ostringstream s;
    for (std::size_t j = 0; j < header.size(); ++j)
      s << (j ? "," : "") << header[j];
    s << '\n' << std::setprecision(10);
    const std::size_t rows = columns.empty() ? 0 : columns[0].size();
    for (std::size_t i = 0; i < rows; ++i)
      {
        for (std::size_t j = 0; j < columns.size(); ++j)
          s << (j ? "," : "") << columns[j][i];
        s << '\n';
      }
    write_text(name, s.str());
  }
  template <int dim>
  void
  OutputDirectory::write_solution(const dealii::DataOutInterface<dim, dim> &data_out) const
  {
    std::ostringstream vtu;
    data_out.write_vtu(vtu);
    write_text("solution-0000.vtu", vtu.str());
    std::ostringstream pvd;
    dealii::DataOutBase::write_pvd_record(pvd, {{0., std::string("solution-0000.vtu")}});
    write_text("solution.pvd", pvd.str());
  }

  template void
  OutputDirectory::write_solution<2>(const dealii::DataOutInterface<2, 2> &) const;
  template void
  OutputDirectory::write_solution<3>(const dealii::DataOutInterface<3, 3> &) const;
} // namespace granflow
