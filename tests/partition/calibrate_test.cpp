// SPDX-License-Identifier: MIT
// measure_calibration (`tgraph calibrate`): what it reports when the machine cannot be measured.
#include <gtest/gtest.h>
#include <pthread.h>
#include <sched.h>

#include <stdexcept>
#include <string>
#include <thread>

#include "tgraph/graph/error.hpp"
#include "tgraph/partition/cost_model.hpp"

namespace tgraph::partition {
namespace {

// On one CPU there is nothing to measure: a failure of the work (exit 1 on the command
// line), not a tgraph::Error about the input (exit 2).
TEST(Calibration, OnOneCpuFailsAsTheWorkNotAsBadInput) {
  bool pinned = false, input_error = false, runtime_error = false;
  std::string what;
  std::thread t([&] {
    cpu_set_t one;
    CPU_ZERO(&one);
    CPU_SET(sched_getcpu(), &one);
    pinned = pthread_setaffinity_np(pthread_self(), sizeof one, &one) == 0;
    try {
      measure_calibration({.rounds = 500});
    } catch (const Error&) {
      input_error = true;
    } catch (const std::runtime_error& e) {
      runtime_error = true;
      what = e.what();
    }
  });
  t.join();
  ASSERT_TRUE(pinned);
  EXPECT_FALSE(input_error);
  EXPECT_TRUE(runtime_error);
  EXPECT_EQ(what, "calibrate: needs two CPUs, this process may use 1");
}

}  // namespace
}  // namespace tgraph::partition
