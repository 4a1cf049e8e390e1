// The output directory (DESIGN.md "Output directory"): summary.json, profiles/*.csv, log.txt and
// the VTU/PVD files. All writing of CSV and JSON lives here. A run writes into a staging directory
// beside the target; commit() moves its files into the target. A run that ends in bad input never
// commits, so nothing a user already has in the target is lost or left half-written.
#pragma once

#include <deal.II/base/data_out_base.h>

#include <nlohmann/json.hpp>

#include <functional>
#include <iosfwd>
#include <string>
#include <vector>

namespace granflow
{
  /// Writes `path` through `write` into a temporary file renamed over it: a reader never sees a
  /// half-written file, and a process stopped while writing leaves an earlier file of that name
  /// whole. Throws std::runtime_error with the system's reason; then nothing is left of it.
  void
  write_file_atomically(const std::string &path, const std::function<void(std::ostream &)> &write);

  class OutputDirectory
  {
  public:
    /// Creates the staging directory (and profiles/); throws InputError if it cannot, if `path`
    /// exists and is not a directory, or if it is an existing directory (or has a profiles/) that
    /// this user cannot write (checked before any work, so no run is lost to it).
    explicit OutputDirectory(const std::string &path);
    /// Removes the staging directory unless committed or kept.
    ~OutputDirectory();
    OutputDirectory(const OutputDirectory &) = delete;
    OutputDirectory &
    operator=(const OutputDirectory &) = delete;

    /// Moves every staged file into the target directory (replacing files of the same name) and
    /// removes the files of an earlier run there that this run did not write; other files stay.
    void
    commit();

    /// Whether a commit() that failed had begun moving files into the target (before that, the
    /// target is as it was: commit() first writes its manifest there).
    bool
    partly_committed() const
    {
      return moving;
    }

    /// For a run that produced no results: leaves the target directory as it was and keeps the
    /// staging directory (path(), with this run's log) instead of removing it; the next run into
    /// the same target removes it.
    void
    keep_staging()
    {
      kept = true;
    }

    /// The target directory, as the user named it.
    const std::string &
    target() const
    {
      return final_path;
    }

    const std::string &
    path() const
    {
      return root;
    }
    std::string
    file(const std::string &name) const;

    /// "<target> was left as it was, and the log of this run is <staging>/log.txt": what a run
    /// that ends before it has results says of its output (keep_staging()).
    std::string
    left_as_it_was() const;

    /// Whether committing would replace `existing` (a path relative to the working directory),
    /// because it is a file of the target whose name a run writes (a case file named
    /// parameters.prm in the output directory).
    bool
    would_replace(const std::string &existing) const;

    /// Whether `path` (as given to file(): relative to the output directory, or absolute) is in
    /// the target directory itself: a file the run writes there directly, not through staging,
    /// is replaced or removed when the run commits, and is there even if the run fails.
    bool
    in_target(const std::string &path) const;

    /// Whether `relative` (a path in an output directory) is the name of a file a run writes.
    static bool
    is_run_file(const std::string &relative);

    /// Writes `content` to `name` atomically (temporary file + rename).
    void
    write_text(const std::string &name, const std::string &content) const;

    void
    write_json(const std::string &name, const nlohmann::json &json) const;

    /// CSV with a header row; columns[0] is the coordinate along the line.
    void
    write_csv(const std::string &name, const std::vector<std::string> &header,
              const std::vector<std::vector<double>> &columns) const;

    /// solution-0000.vtu from `data_out` (patches already built) and the solution.pvd that lists
    /// it.
    template <int dim>
    void
    write_solution(const dealii::DataOutInterface<dim, dim> &data_out) const;

  private:
    std::string final_path;
    std::string root; // staging directory while running, target after commit()
    bool        committed = false;
    bool        kept      = false;
    bool        moving    = false; // commit() has begun to move files into the target
    /// Held while this object lives, one run per target (released also when the constructor
    /// throws after taking it).
    struct Lock
    {
      std::string path;
      int         fd     = -1;
      Lock()             = default;
      Lock(const Lock &) = delete;
      Lock &
      operator=(const Lock &) = delete;
      ~Lock();
    } lock;
  };
} // namespace granflow
