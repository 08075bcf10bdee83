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

TEST(Strings, QuotesHexAndNamespaces) {
    EXPECT_EQ(inQuotes("HitGroup_Pacman"), "'HitGroup_Pacman'");
    EXPECT_EQ(hexText(0xE0F80), "0xE0F80");
    EXPECT_EQ(hexText(0x1F, 4), "0x001F");
    EXPECT_EQ(hexText(0), "0x0");
    EXPECT_EQ(withoutNamespace("refray::procedural::d3d12::RayPayload"), "RayPayload");
    EXPECT_EQ(withoutNamespace("RayPayload"), "RayPayload");
}

TEST(Strings, ShellQuotedWordsSurviveTheShell) {
    EXPECT_EQ(shellQuoted("steps=0.5"), "steps=0.5");
    EXPECT_EQ(shellQuoted("/tmp/a-b/c_d.json"), "/tmp/a-b/c_d.json");
    EXPECT_EQ(shellQuoted("my dir"), "'my dir'");
    EXPECT_EQ(shellQuoted("it's"), "'it'\\''s'");
    EXPECT_EQ(shellQuoted(""), "''");
    EXPECT_EQ(shellQuoted("$HOME"), "'$HOME'");
}
