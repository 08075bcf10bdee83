// Where a test writes its files.
#pragma once

#include <gtest/gtest.h>

#include <filesystem>
#include <string>

namespace refray::testing {

// REFRAY_TEST_OUTPUT_DIR/group/Suite.Test, created. ctest runs several processes at a time (a suite each, or a test
// each for the lavapipe and discrimination binaries; tests/CMakeLists.txt), so files that more than one test writes
// under one name must live apart: one test rewriting a file while another reads it lets the reader see it empty or
// half written.
inline std::filesystem::path testOutputDirectory(const std::string& group) {
    const ::testing::TestInfo* test = ::testing::UnitTest::GetInstance()->current_test_info();
    std::filesystem::path directory = std::filesystem::path(REFRAY_TEST_OUTPUT_DIR) / group;
    if (test) directory /= std::string(test->test_suite_name()) + "." + test->name();
    std::filesystem::create_directories(directory);
    return directory;
}

}  // namespace refray::testing
