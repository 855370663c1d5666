// Expected and Status: the value-or-message types every reader of untrusted bytes returns.
#include "qvr/core/expected.h"

#include <memory>
#include <string>
#include <utility>

#include <gtest/gtest.h>

namespace qvr {
namespace {

Expected<int> half(int x) {
    if (x % 2 != 0)
        return makeError("odd: " + std::to_string(x));
    return x / 2;
}

TEST(Expected, HoldsValueWhenConstructedFromValue) {
    Expected<int> e = half(8);
    ASSERT_TRUE(e.ok());
    EXPECT_TRUE(static_cast<bool>(e));
    EXPECT_EQ(e.value(), 4);
    EXPECT_EQ(*e, 4);
    *e = 9;
    EXPECT_EQ(e.value(), 9);
}

TEST(Expected, HoldsMessageWhenConstructedFromError) {
    Expected<int> e = half(7);
    ASSERT_FALSE(e.ok());
    EXPECT_FALSE(static_cast<bool>(e));
    EXPECT_EQ(e.error(), "odd: 7");
}

TEST(Expected, MovesOutMoveOnlyValueWhenRvalue) {
    Expected<std::unique_ptr<int>> e = std::make_unique<int>(42);
    ASSERT_TRUE(e.ok());
    EXPECT_EQ(**e, 42);
    std::unique_ptr<int> p = std::move(e).value();
    ASSERT_NE(p, nullptr);
    EXPECT_EQ(*p, 42);
}

TEST(Expected, GivesMemberAccessWhenArrowUsed) {
    Expected<std::string> e = std::string("abc");
    EXPECT_EQ(e->size(), 3u);
    const Expected<std::string>& c = e;
    EXPECT_EQ(c->front(), 'a');
}

TEST(Expected, AbortsWhenValueReadFromError) {
    EXPECT_DEATH(
        {
            Expected<int> e = makeError("boom");
            (void)e.value();
        },
        "value\\(\\) on an error");
}

TEST(Expected, AbortsWhenErrorReadFromValue) {
    EXPECT_DEATH(
        {
            Expected<int> e = 3;
            (void)e.error();
        },
        "error\\(\\) on a value");
}

TEST(Status, IsSuccessWhenDefault) {
    Status s;
    EXPECT_TRUE(s.ok());
    EXPECT_TRUE(static_cast<bool>(s));
    EXPECT_TRUE(s.error().empty());
    EXPECT_TRUE(Status::success().ok());
}

TEST(Status, CarriesMessageWhenFailed) {
    Status s = makeError("disk on fire");
    EXPECT_FALSE(s.ok());
    EXPECT_FALSE(static_cast<bool>(s));
    EXPECT_EQ(s.error(), "disk on fire");
    // An error with an empty message is still a failure.
    Status empty = makeError("");
    EXPECT_FALSE(empty.ok());
}

}  // namespace
}  // namespace qvr
