#pragma once
// A measured figure in the test report (ctest / --gtest_output), where docs/stability.md's table
// come from: test::record("rel_error", 3.2e-7) shows as rel_error="3.200e-07".
#include <gtest/gtest.h>

#include <cstdio>

namespace radiosa::test {

inline void record(const char* key, double value) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.3e", value);
    ::testing::Test::RecordProperty(key, buf);
}

}  // namespace radiosa::test
