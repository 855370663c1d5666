// Design names on the command line (runtime_design.h): the paper's five designs and a fixed
// fovea of any e1 ("fixed:E", issue 15's sweep), each list item parsed or refused with a message
// that names it.
#include "qvr/runtime/runtime_design.h"

#include <gtest/gtest.h>

#include <string>

namespace qvr::runtime {
namespace {

TEST(DesignSpec, AcceptsFixedEWithItsE1AndLabel) {
    auto ten = designSpecByName("fixed:10");
    ASSERT_TRUE(ten.ok()) << ten.error();
    EXPECT_EQ(ten->design, RuntimeDesign::kFixed);
    EXPECT_DOUBLE_EQ(ten->fixed_e1_deg, 10.0);
    EXPECT_EQ(ten->label(), "fixed:10");
    auto half = designSpecByName("fixed:7.5");
    ASSERT_TRUE(half.ok()) << half.error();
    EXPECT_DOUBLE_EQ(half->fixed_e1_deg, 7.5);
    EXPECT_EQ(half->label(), "fixed:7.5");
    // The ends of the range are in it.
    for (const double e1 : {kFixedE1MinDeg, kFixedE1MaxDeg}) {
        auto edge = designSpecByName("fixed:" + std::to_string(e1));
        ASSERT_TRUE(edge.ok()) << e1 << ": " << edge.error();
        EXPECT_DOUBLE_EQ(edge->fixed_e1_deg, e1);
    }
    EXPECT_EQ(designLabel(RuntimeDesign::kFixed, 2.0), "fixed:2");
}

TEST(DesignSpec, KeepsTheNamedDesignsAndFfrAtFiveDegrees) {
    for (RuntimeDesign d : allRuntimeDesigns()) {
        auto spec = designSpecByName(designName(d));
        ASSERT_TRUE(spec.ok()) << designName(d) << ": " << spec.error();
        EXPECT_EQ(spec->design, d);
        EXPECT_EQ(spec->label(), designName(d));
    }
    auto ffr = designSpecByName("ffr");
    ASSERT_TRUE(ffr.ok());
    EXPECT_EQ(ffr->design, RuntimeDesign::kFfr);
    EXPECT_DOUBLE_EQ(ffr->fixed_e1_deg, 5.0);
    EXPECT_DOUBLE_EQ(kFfrE1Deg, 5.0);
    EXPECT_EQ(ffr->label(), "ffr");
}

TEST(DesignSpec, RejectsFixedWithoutAValidE1WithAMessageNamingIt) {
    for (const std::string bad :
         {"fixed:", "fixed:0", "fixed:0.5", "fixed:-5", "fixed:abc", "fixed:10abc", "fixed:1e9",
          "fixed:nan", "fixed:NaN", "fixed:inf", "fixed:-inf", "fixed:90.5", "fixed:1e999", "fixed",
          "fixed:10:2", "FIXED:10", "fixed10", "dfr", ""}) {
        auto spec = designSpecByName(bad);
        EXPECT_FALSE(spec.ok()) << "'" << bad << "' was accepted";
        if (!spec.ok() && !bad.empty()) {
            EXPECT_NE(spec.error().find(bad), std::string::npos)
                << "'" << bad << "': " << spec.error();
        }
    }
    // A bare "fixed" asks for its e1.
    auto bare = designSpecByName("fixed");
    ASSERT_FALSE(bare.ok());
    EXPECT_NE(bare.error().find("fixed:E"), std::string::npos) << bare.error();
}

TEST(RuntimeDesigns, ParseListsOfNamesAndFixedDesigns) {
    auto d = parseDesignList("local,qvr");
    ASSERT_TRUE(d.ok()) << d.error();
    ASSERT_EQ(d->size(), 2u);
    EXPECT_EQ((*d)[0].design, RuntimeDesign::kLocal);
    EXPECT_EQ((*d)[1].design, RuntimeDesign::kQvr);
    auto sweep = parseDesignList("fixed:2,ffr,fixed:10,qvr,sw,fixed:30");
    ASSERT_TRUE(sweep.ok()) << sweep.error();
    ASSERT_EQ(sweep->size(), 6u);
    const char* labels[] = {"fixed:2", "ffr", "fixed:10", "qvr", "sw", "fixed:30"};
    for (size_t i = 0; i < 6; ++i)
        EXPECT_EQ((*sweep)[i].label(), labels[i]);
    EXPECT_DOUBLE_EQ((*sweep)[0].fixed_e1_deg, 2.0);
    EXPECT_DOUBLE_EQ((*sweep)[1].fixed_e1_deg, 5.0);
    EXPECT_DOUBLE_EQ((*sweep)[5].fixed_e1_deg, 30.0);
    // Empty items are skipped.
    auto gaps = parseDesignList(",ffr,,fixed:3,");
    ASSERT_TRUE(gaps.ok()) << gaps.error();
    EXPECT_EQ(gaps->size(), 2u);
}

TEST(RuntimeDesigns, RejectListsWithABadOrRepeatedDesign) {
    for (const std::string bad : {"local,dfr", "", ",", "qvr,fixed:", "fixed:0,qvr", "ffr,fixed",
                                  "qvr,fixed:nan", "fixed:1e9"}) {
        auto d = parseDesignList(bad);
        EXPECT_FALSE(d.ok()) << "'" << bad << "' was accepted";
    }
    // Each design once: a second run of the same one would overwrite the first's results.
    for (const std::string twice : {"qvr,ffr,qvr", "fixed:10,fixed:10", "fixed:10,fixed:10.0",
                                    "ffr,ffr", "fixed:5,sw,fixed:5"}) {
        auto d = parseDesignList(twice);
        ASSERT_FALSE(d.ok()) << "'" << twice << "' was accepted";
        EXPECT_NE(d.error().find("twice"), std::string::npos) << d.error();
    }
}

}  // namespace
}  // namespace qvr::runtime
