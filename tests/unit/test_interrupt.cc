// Stop requests (core/interrupt.h): polled by the solvers, except inside a BeforeResults scope,
// where a signal ends the process at once (nothing computed that could be written).
#include "core/interrupt.h"

#include <gtest/gtest.h>

#include <csignal>
#include <cstdlib>

namespace
{
  using namespace granflow;

  class InterruptDeathTest : public ::testing::Test
  {
  protected:
    void
    SetUp() override
    {
      // fork and exec: the child starts with the handler state of a fresh process
      GTEST_FLAG_SET(death_test_style, "threadsafe");
    }
  };

  TEST_F(InterruptDeathTest, SignalInsideTheScopeEndsTheProcessAtOnceWithItsOutcome)
  {
    EXPECT_EXIT(
        {
          interrupt::install();
          const interrupt::BeforeResults scope("out was left as it was");
          std::raise(SIGTERM);
          std::exit(0); // not reached
        },
        ::testing::ExitedWithCode(128 + SIGTERM),
        "stopped by SIGTERM before it had results to write.*out was left as it was");
  }

  TEST_F(InterruptDeathTest, SignalBeforeTheScopeEndsTheProcessWhenItBegins)
  {
    EXPECT_EXIT(
        {
          interrupt::install();
          std::raise(SIGINT);
          if (!interrupt::requested())
            std::exit(1);
          const interrupt::BeforeResults scope("kept");
          std::exit(0); // not reached
        },
        ::testing::ExitedWithCode(128 + SIGINT),
        "stopped by SIGINT before it had results to write.*kept");
  }

  TEST_F(InterruptDeathTest, AfterTheScopeASignalIsOnlyARequest)
  {
    EXPECT_EXIT(
        {
          interrupt::install();
          {
            const interrupt::BeforeResults scope("kept");
          }
          std::raise(SIGTERM);
          std::exit(interrupt::requested() && interrupt::signal_number() == SIGTERM ? 7 : 1);
        },
        ::testing::ExitedWithCode(7), "stopping at the next iteration");
  }
} // namespace
