// Design names on the command line (core/design.h): the paper's seven for the simulator, the
// runtime's five and a fixed fovea of any e1 ("fixed:E") for the runtime, each list item parsed
// or refused with a message that names it, and every name and label read back to its design.
#include "qvr/core/design.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <string>

namespace qvr {
namespace {

Expected<DesignSpec> rt(const std::string& name) {
    return parseDesign(name, DesignScope::Runtime);
}

TEST(DesignSpec, AcceptsFixedEWithItsE1AndLabel) {
    auto ten = rt("fixed:10");
    ASSERT_TRUE(ten.ok()) << ten.error();
    EXPECT_EQ(ten->design, Design::Fixed);
    EXPECT_DOUBLE_EQ(ten->fixed_e1_deg, 10.0);
    EXPECT_EQ(ten->label(), "fixed:10");
    auto half = rt("fixed:7.5");
    ASSERT_TRUE(half.ok()) << half.error();
    EXPECT_DOUBLE_EQ(half->fixed_e1_deg, 7.5);
    EXPECT_EQ(half->label(), "fixed:7.5");
    // The ends of the range are in it.
    for (const double e1 : {kFixedE1MinDeg, kFixedE1MaxDeg}) {
        auto edge = rt("fixed:" + std::to_string(e1));
        ASSERT_TRUE(edge.ok()) << e1 << ": " << edge.error();
        EXPECT_DOUBLE_EQ(edge->fixed_e1_deg, e1);
    }
    EXPECT_EQ(designLabel(Design::Fixed, 2.0), "fixed:2");
}

TEST(DesignSpec, KeepsTheNamedDesignsAndFfrAtFiveDegrees) {
    for (Design d : runtimeDesigns()) {
        const std::string name(traitsOf(d).name);
        auto spec = rt(name);
        ASSERT_TRUE(spec.ok()) << name << ": " << spec.error();
        EXPECT_EQ(spec->design, d);
        EXPECT_EQ(spec->label(), name);
    }
    auto ffr = rt("ffr");
    ASSERT_TRUE(ffr.ok());
    EXPECT_EQ(ffr->design, Design::Ffr);
    EXPECT_DOUBLE_EQ(ffr->fixed_e1_deg, 5.0);
    EXPECT_DOUBLE_EQ(kFfrE1Deg, 5.0);
    EXPECT_EQ(ffr->label(), "ffr");
}

TEST(DesignSpec, RejectsFixedWithoutAValidE1WithAMessageNamingIt) {
    for (const std::string bad :
         {"fixed:", "fixed:0", "fixed:0.5", "fixed:-5", "fixed:abc", "fixed:10abc", "fixed:1e9",
          "fixed:nan", "fixed:NaN", "fixed:inf", "fixed:-inf", "fixed:90.5", "fixed:1e999", "fixed",
          "fixed:10:2", "FIXED:10", "fixed10", "dfr", ""}) {
        auto spec = rt(bad);
        EXPECT_FALSE(spec.ok()) << "'" << bad << "' was accepted";
        if (!spec.ok() && !bad.empty()) {
            EXPECT_NE(spec.error().find(bad), std::string::npos)
                << "'" << bad << "': " << spec.error();
        }
    }
    // A bare "fixed" asks for its e1.
    auto bare = rt("fixed");
    ASSERT_FALSE(bare.ok());
    EXPECT_NE(bare.error().find("fixed:E"), std::string::npos) << bare.error();
}

TEST(Designs, ParseListsOfNamesAndFixedDesigns) {
    auto d = parseDesignList("local,qvr", DesignScope::Runtime);
    ASSERT_TRUE(d.ok()) << d.error();
    ASSERT_EQ(d->size(), 2u);
    EXPECT_EQ((*d)[0].design, Design::Local);
    EXPECT_EQ((*d)[1].design, Design::Qvr);
    auto sweep = parseDesignList("fixed:2,ffr,fixed:10,qvr,sw,fixed:30", DesignScope::Runtime);
    ASSERT_TRUE(sweep.ok()) << sweep.error();
    ASSERT_EQ(sweep->size(), 6u);
    const char* labels[] = {"fixed:2", "ffr", "fixed:10", "qvr", "sw", "fixed:30"};
    for (size_t i = 0; i < 6; ++i)
        EXPECT_EQ((*sweep)[i].label(), labels[i]);
    EXPECT_DOUBLE_EQ((*sweep)[0].fixed_e1_deg, 2.0);
    EXPECT_DOUBLE_EQ((*sweep)[1].fixed_e1_deg, 5.0);
    EXPECT_DOUBLE_EQ((*sweep)[5].fixed_e1_deg, 30.0);
    // Empty items are skipped.
    auto gaps = parseDesignList(",ffr,,fixed:3,", DesignScope::Runtime);
    ASSERT_TRUE(gaps.ok()) << gaps.error();
    EXPECT_EQ(gaps->size(), 2u);
}

TEST(Designs, RejectListsWithABadOrRepeatedDesign) {
    for (const std::string bad : {"local,dfr", "", ",", "qvr,fixed:", "fixed:0,qvr", "ffr,fixed",
                                  "qvr,fixed:nan", "fixed:1e9"}) {
        auto d = parseDesignList(bad, DesignScope::Runtime);
        EXPECT_FALSE(d.ok()) << "'" << bad << "' was accepted";
    }
    // Each design once: a second run of the same one would overwrite the first's results.
    for (const std::string twice : {"qvr,ffr,qvr", "fixed:10,fixed:10", "fixed:10,fixed:10.0",
                                    "ffr,ffr", "fixed:5,sw,fixed:5"}) {
        auto d = parseDesignList(twice, DesignScope::Runtime);
        ASSERT_FALSE(d.ok()) << "'" << twice << "' was accepted";
        EXPECT_NE(d.error().find("twice"), std::string::npos) << d.error();
    }
}

// Every design the simulator names, and every label the runtime writes, reads back to itself.
TEST(Designs, NamesAndLabelsRoundTrip) {
    for (Design d : allDesigns()) {
        const std::string name(traitsOf(d).name);
        auto back = designByName(name);
        ASSERT_TRUE(back.ok()) << name << ": " << back.error();
        EXPECT_EQ(*back, d);
        EXPECT_EQ(traitsOf(d).design, d);
        EXPECT_NE(designNamesList().find(name), std::string::npos);
    }
    for (const std::string label :
         {"local", "remote", "ffr", "sw", "qvr", "fixed:2", "fixed:7.5", "fixed:90"}) {
        auto spec = rt(label);
        ASSERT_TRUE(spec.ok()) << label << ": " << spec.error();
        EXPECT_EQ(spec->label(), label);
        auto again = rt(spec->label());
        ASSERT_TRUE(again.ok());
        EXPECT_EQ(again->design, spec->design);
        EXPECT_DOUBLE_EQ(again->fixed_e1_deg, spec->fixed_e1_deg);
    }
    EXPECT_EQ(traitsOf(Design::Fixed).design, Design::Fixed);
    EXPECT_EQ(traitsOf(Design::Fixed).policy, "fixed");
}

// The runtime runs five of the seven; the other two stay valid simulator names and are refused
// by the runtime with a message saying why.
TEST(Designs, TheRuntimeRefusesTheSimulatedOnlyDesignsByName) {
    for (const std::string name : {"static", "dfr"}) {
        EXPECT_TRUE(designByName(name).ok()) << name;
        EXPECT_FALSE(traitsOf(*designByName(name)).runtime);
        auto r = rt(name);
        ASSERT_FALSE(r.ok()) << name;
        EXPECT_NE(r.error().find("'" + name + "'"), std::string::npos) << r.error();
        EXPECT_NE(r.error().find("simulated only"), std::string::npos) << r.error();
    }
    for (Design d : runtimeDesigns())
        EXPECT_TRUE(traitsOf(d).runtime) << traitsOf(d).name;
    EXPECT_FALSE(usesServer(Design::Local));
    EXPECT_TRUE(usesServer(Design::Remote));
    EXPECT_TRUE(usesServer(Design::Fixed));
}

// The simulator reads the paper's seven only: fixed:E and the bad names are refused by name.
TEST(Designs, TheSimulatorRefusesUnknownNamesAndFixedE) {
    for (const std::string bad : {"fixed:10", "fixed", "", "QVR", "qvr ", "local,qvr", "Fixed"}) {
        auto d = designByName(bad);
        ASSERT_FALSE(d.ok()) << "'" << bad << "' was accepted";
        EXPECT_NE(d.error().find("'" + bad + "'"), std::string::npos) << d.error();
    }
    auto list = parseDesignList("local,static,dfr", DesignScope::Simulator);
    ASSERT_TRUE(list.ok()) << list.error();
    EXPECT_EQ(list->size(), 3u);
    EXPECT_FALSE(parseDesignList("local,fixed:3", DesignScope::Simulator).ok());
}

// aimd, the network-driven baseline, is a design of the runtime (and its model) and of the
// simulator, outside the paper's seven that the simulator's evaluation compares.
TEST(Designs, AimdIsNamedInBothScopesButIsNotOneOfThePapersSeven) {
    for (DesignScope scope : {DesignScope::Runtime, DesignScope::Simulator}) {
        auto spec = parseDesign("aimd", scope);
        ASSERT_TRUE(spec.ok()) << spec.error();
        EXPECT_EQ(spec->design, Design::Aimd);
        EXPECT_EQ(spec->label(), "aimd");
    }
    EXPECT_EQ(traitsOf(Design::Aimd).design, Design::Aimd);
    EXPECT_EQ(traitsOf(Design::Aimd).policy, "aimd");
    EXPECT_TRUE(traitsOf(Design::Aimd).runtime);
    EXPECT_TRUE(usesServer(Design::Aimd));
    EXPECT_EQ(std::count(allDesigns().begin(), allDesigns().end(), Design::Aimd), 0);
    EXPECT_EQ(std::count(runtimeDesigns().begin(), runtimeDesigns().end(), Design::Aimd), 1);
    auto list = parseDesignList("qvr,aimd,fixed:10", DesignScope::Runtime);
    ASSERT_TRUE(list.ok()) << list.error();
    EXPECT_EQ((*list)[1].design, Design::Aimd);
}

}  // namespace
}  // namespace qvr
