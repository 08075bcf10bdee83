#include <gtest/gtest.h>

#include "core/strings.h"

using namespace refray;

TEST(Strings, EditDistanceCountsEdits) {
    EXPECT_EQ(editDistance("kitten", "sitting"), 3u);
    EXPECT_EQ(editDistance("", "abc"), 3u);
    EXPECT_EQ(editDistance("Miss", "miss"), 0u);  // case-insensitive
}

TEST(Strings, DidYouMeanSuggestsCloseNamesOnly) {
    const std::vector<std::string> names = {"ClosestHit_Pacman", "Intersection_Mandelbulb", "Miss"};
    EXPECT_EQ(didYouMean("ClosestHit_Pacmn", names), " (did you mean 'ClosestHit_Pacman'?)");
    EXPECT_EQ(didYouMean("SomethingElseEntirely", names), "");
}
