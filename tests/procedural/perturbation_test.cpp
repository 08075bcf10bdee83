// Tests procedural/perturbation.h: the option names the command line parses and what a render's metadata records.
#include "procedural/perturbation.h"

#include <gtest/gtest.h>

namespace refray::procedural {
namespace {

TEST(Perturbation, NamesRoundTrip) {
    for (const Contraction c : {Contraction::Split, Contraction::Fuse, Contraction::Mixed})
        EXPECT_EQ(parseContraction(toString(c)), c);
    for (const Denormals d : {Denormals::Flush, Denormals::Preserve}) EXPECT_EQ(parseDenormals(toString(d)), d);
    EXPECT_FALSE(parseContraction("fused"));
    EXPECT_FALSE(parseDenormals("ftz"));
}

TEST(Perturbation, DescriptionNamesTheSeedTheOptionsAndTheModel) {
    EXPECT_EQ(describe(Perturbation{}), "seed 0, contraction mixed, denormals flush (variation model v1)");
    EXPECT_EQ(describe(Perturbation{12, Contraction::Split, Denormals::Preserve}),
              "seed 12, contraction split, denormals preserve (variation model v1)");
}

}  // namespace
}  // namespace refray::procedural
