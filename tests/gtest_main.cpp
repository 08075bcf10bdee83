// The main of every refray test binary: GoogleTest's, except that a run in which no test passed or failed (every
// test it selected skipped itself, such as the lavapipe cross-checks on a machine without lavapipe, or none was
// selected) exits 77, which CTest reports as skipped (SKIP_RETURN_CODE, tests/gtest_suites.cmake) rather than as a
// pass. A failure still exits 1.
#include <gtest/gtest.h>

#include <string_view>

namespace {
// GoogleTest's own help flags: a run that only prints the help runs no test and is not a skip.
bool asksForHelp(int argc, char** argv) {
    for (int i = 1; i < argc; ++i) {
        const std::string_view arg = argv[i];
        if (arg == "--help" || arg == "-h" || arg == "-?" || arg == "/?" || arg == "--gtest_help") return true;
    }
    return false;
}
}  // namespace

int main(int argc, char** argv) {
    const bool help = asksForHelp(argc, argv);
    ::testing::InitGoogleTest(&argc, argv);
    const int result = RUN_ALL_TESTS();
    const ::testing::UnitTest& unit = *::testing::UnitTest::GetInstance();
    if (result == 0 && unit.successful_test_count() == 0 && unit.failed_test_count() == 0 &&
        !::testing::GTEST_FLAG(list_tests) && !help)
        return 77;
    return result;
}
