// The progress line's time left (core/time_left.h): the pace of the last steps carried to the end.
#include "core/time_left.h"

#include <gtest/gtest.h>

using granflow::TimeLeft;

TEST(TimeLeft, CarriesThePaceOfTheLastStepsToTheEnd)
{
  TimeLeft t(10., 1.);
  EXPECT_FALSE(t.seconds_to(10.)); // no steps
  t.record(0., 0.);
  EXPECT_FALSE(t.seconds_to(10.)); // one step: no pace
  t.record(0.5, 0.5);
  EXPECT_FALSE(t.seconds_to(10.)); // a pace over less than a second says little
  t.record(2., 1.);
  ASSERT_TRUE(t.seconds_to(10.));
  EXPECT_DOUBLE_EQ(*t.seconds_to(10.), 18.); // 1 per 2 s, 9 to go
  // Only the last 10 s count: a slower pace since then is what the estimate follows.
  for (double now = 4.; now <= 30.; now += 2.)
    t.record(now, 1. + (now - 2.) / 4.); // 1 per 4 s from t = 2 s
  ASSERT_TRUE(t.seconds_to(10.));
  EXPECT_DOUBLE_EQ(*t.seconds_to(10.), (10. - 8.) * 4.);
}

TEST(TimeLeft, HasNoEstimateWithoutProgressOrAfterARestart)
{
  TimeLeft t(10., 1.);
  t.record(0., 1.);
  t.record(5., 1.);
  EXPECT_FALSE(t.seconds_to(2.)); // no progress in 5 s: no pace
  t.record(6., 2.);
  EXPECT_TRUE(t.seconds_to(3.));
  t.restart();
  EXPECT_FALSE(t.seconds_to(3.));
  t.record(7., 2.);
  EXPECT_FALSE(t.seconds_to(3.)); // one step since the restart
  t.record(9., 3.);
  EXPECT_DOUBLE_EQ(*t.seconds_to(4.), 2.);
  // Steps far apart keep the last two, whatever the window.
  t.record(100., 4.);
  ASSERT_TRUE(t.seconds_to(5.));
  EXPECT_DOUBLE_EQ(*t.seconds_to(5.), 91.);
}
