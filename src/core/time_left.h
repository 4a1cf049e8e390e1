// The time a run has left, for its progress line (DESIGN.md: progress with step, time, residual and
// ETA): the pace of its last steps, in progress per wall second, carried to the end.
#pragma once

#include <deque>
#include <optional>
#include <utility>

namespace granflow
{
  class TimeLeft
  {
  public:
    /// The pace is that of the steps of the last `window` seconds; there is no estimate until it
    /// spans at least `min_span` seconds.
    explicit TimeLeft(const double window = 10., const double min_span = 1.)
        : window(window)
        , min_span(min_span)
    {
    }

    /// A step ended at wall time `now` (s) with `done` of the run's progress done.
    void
    record(const double now, const double done)
    {
      steps.emplace_back(now, done);
      while (steps.size() > 2 && steps.front().first < now - window)
        steps.pop_front();
    }

    /// Forgets the steps so far: what follows will go at another pace (ngf's increments while
    /// they grow).
    void
    restart()
    {
      steps.clear();
    }

    /// Seconds to reach `total` progress at the recorded pace, if there is one.
    std::optional<double>
    seconds_to(const double total) const
    {
      if (steps.size() < 2)
        return std::nullopt;
      const double span     = steps.back().first - steps.front().first;
      const double advanced = steps.back().second - steps.front().second;
      if (span < min_span || !(advanced > 0.))
        return std::nullopt;
      return (total - steps.back().second) / advanced * span;
    }

  private:
    double                                window, min_span;
    std::deque<std::pair<double, double>> steps; // (wall time, progress)
  };
} // namespace granflow
