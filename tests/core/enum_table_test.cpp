#include "qvr/core/enum_table.h"

#include <gtest/gtest.h>

namespace qvr {
namespace {

enum class Colour { kRed, kGreen, kBlue };

constexpr EnumName<Colour> kColourNames[] = {{Colour::kRed, "red"}, {Colour::kGreen, "green"}};

struct ColourRow {
    Colour value;
    const char* name;
    int wavelength_nm;
};
constexpr ColourRow kColourRows[] = {{Colour::kRed, "red", 700}, {Colour::kBlue, "blue", 450}};

TEST(EnumTable, NamesAValueAndFallsBackForOneWithoutARow) {
    EXPECT_STREQ(enumName(kColourNames, Colour::kGreen), "green");
    EXPECT_STREQ(enumName(kColourNames, Colour::kBlue), "?");
    EXPECT_STREQ(enumName(kColourNames, Colour::kBlue, "none"), "none");
}

TEST(EnumTable, ParsesANameAndRefusesAnUnknownOne) {
    EXPECT_EQ(enumFromName(kColourNames, "red"), Colour::kRed);
    EXPECT_EQ(enumFromName(kColourRows, "blue"), Colour::kBlue);
    EXPECT_FALSE(enumFromName(kColourNames, "blue").has_value());
    EXPECT_FALSE(enumFromName(kColourNames, "").has_value());
}

TEST(EnumTable, FindsTheRowWithItsOtherColumns) {
    ASSERT_NE(enumRow(kColourRows, Colour::kBlue), nullptr);
    EXPECT_EQ(enumRow(kColourRows, Colour::kBlue)->wavelength_nm, 450);
    EXPECT_EQ(enumRow(kColourRows, Colour::kGreen), nullptr);
    static_assert(enumRow(kColourRows, Colour::kRed)->wavelength_nm == 700);
}

}  // namespace
}  // namespace qvr
