#include <gtest/gtest.h>

#include <vector>

#include "core/progress.h"

using namespace refray;

TEST(Progress, ReportsFinishWithEverythingDone) {
    std::vector<ProgressState> seen;
    Progress p("work", 10, [&](const ProgressState& s) { seen.push_back(s); }, std::chrono::milliseconds(0));
    for (int i = 0; i < 10; ++i) p.advance();
    p.finish();
    ASSERT_FALSE(seen.empty());
    EXPECT_TRUE(seen.back().finished);
    EXPECT_EQ(seen.back().done, 10u);
    EXPECT_EQ(p.done(), 10u);
}

TEST(Progress, BarShowsPercentAndEta) {
    ProgressState s;
    s.label = "render";
    s.done = 5;
    s.total = 10;
    s.elapsedSeconds = 2.0;
    s.etaSeconds = 2.0;
    const std::string bar = formatProgressBar(s, 10);
    EXPECT_NE(bar.find("#####....."), std::string::npos);
    EXPECT_NE(bar.find("50%"), std::string::npos);
    EXPECT_NE(bar.find("ETA 2.0s"), std::string::npos);
}
