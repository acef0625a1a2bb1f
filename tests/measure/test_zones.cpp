// Unit tests of the zones-file parser and look-ups (src-liggghts-eepa/physics/zones.h).
#include <gtest/gtest.h>

#include <stdexcept>
#include <string>

#include "zones.h"

namespace {

using tsg::zones::find_zone;
using tsg::zones::parse_zones_text;
using tsg::zones::ZoneType;

// What meshes/tsg_meshes/build.py writes (comment lines, scientific notation).
const char *kGenerated =
    "# tsg_meshes zones: consigma1-periodic (C7/6 K6x60R C7/6), ends periodic, tolerance 0.0001 m\n"
    "# index type x_start_m x_end_m free_volume_m3\n"
    "1 conveying 0.0000000000e+00 2.9166666667e-02 1.9146000000e-05\n"
    "2 kneading 2.9166666667e-02 3.5416666667e-02 4.1027000000e-06\n"
    "3 kneading 3.5416666667e-02 4.1666666667e-02 4.1027000000e-06\n"
    "\n"
    "   # an indented comment\n"
    "4 chopping 5.0e-02 6.0e-02 6.5e-06\n";

// The message of the std::invalid_argument thrown by parsing `text`, or "" when none is thrown.
std::string error_of(const std::string &text) {
  try {
    parse_zones_text(text, "zones.txt");
  } catch (const std::invalid_argument &e) {
    return e.what();
  }
  return "";
}

TEST(ZonesFile, ParsesTheGeneratorFormat) {
  const auto zones = parse_zones_text(kGenerated, "zones.txt");
  ASSERT_EQ(zones.size(), 4u);
  EXPECT_EQ(zones[0].index, 1);
  EXPECT_EQ(zones[0].type, ZoneType::conveying);
  EXPECT_EQ(zones[1].type, ZoneType::kneading);
  EXPECT_EQ(zones[3].type, ZoneType::chopping);
  EXPECT_DOUBLE_EQ(zones[0].x_end, 2.9166666667e-02);
  EXPECT_DOUBLE_EQ(zones[1].x_start, zones[0].x_end);  // adjacent zones are allowed
  EXPECT_DOUBLE_EQ(zones[3].free_volume, 6.5e-06);
  EXPECT_EQ(zones[3].line, 8);  // line numbers count comments and blank lines
}

TEST(ZonesFile, AcceptsWindowsLineEndings) {
  const auto zones = parse_zones_text("# c\r\n1 conveying 0 0.01 1e-6\r\n2 kneading 0.01 0.02 1e-6\r\n", "z");
  ASSERT_EQ(zones.size(), 2u);
  EXPECT_DOUBLE_EQ(zones[1].free_volume, 1e-6);
}

struct BadCase {
  const char *name;
  const char *text;
  const char *expected[3];  // substrings of the message
};

class BadZonesFile : public ::testing::TestWithParam<BadCase> {};

TEST_P(BadZonesFile, NamesTheLineAndTheReason) {
  const BadCase &c = GetParam();
  const std::string message = error_of(c.text);
  ASSERT_FALSE(message.empty()) << c.name << ": no error";
  EXPECT_NE(message.find("zones.txt"), std::string::npos) << message;
  for (const char *part : c.expected)
    if (part) {
      EXPECT_NE(message.find(part), std::string::npos) << c.name << ": '" << part << "' not in: " << message;
    }
}

INSTANTIATE_TEST_SUITE_P(
    Cases, BadZonesFile,
    ::testing::Values(
        BadCase{"empty", "# only comments\n\n", {"no zones", nullptr, nullptr}},
        BadCase{"four fields", "1 conveying 0 0.01\n", {"line 1", "expected 5 fields", "found 4"}},
        BadCase{"six fields", "# c\n1 conveying 0 0.01 1e-6 7\n", {"line 2", "found 6", nullptr}},
        BadCase{"index not integer", "1.5 conveying 0 0.01 1e-6\n", {"line 1", "index '1.5'", "not an integer"}},
        BadCase{"index out of sequence", "1 conveying 0 0.01 1e-6\n3 kneading 0.01 0.02 1e-6\n",
                {"line 2", "index 3 out of sequence", "expected 2"}},
        BadCase{"unknown type", "1 mixing 0 0.01 1e-6\n", {"line 1", "type 'mixing'", "conveying, kneading, chopping"}},
        BadCase{"number with unit", "1 conveying 0 0.01m 1e-6\n", {"line 1", "x_end '0.01m'", "not a finite number"}},
        BadCase{"nan", "1 conveying nan 0.01 1e-6\n", {"line 1", "x_start 'nan'", nullptr}},
        BadCase{"empty zone", "1 conveying 0.01 0.01 1e-6\n", {"line 1", "x_end 0.01 must be greater than x_start", nullptr}},
        BadCase{"reversed zone", "1 conveying 0.02 0.01 1e-6\n", {"line 1", "greater than x_start 0.02", nullptr}},
        BadCase{"zero free volume", "1 conveying 0 0.01 0\n", {"line 1", "free_volume 0 must be positive", nullptr}},
        BadCase{"negative free volume", "1 conveying 0 0.01 -1e-6\n", {"line 1", "must be positive", nullptr}},
        BadCase{"unsorted", "1 conveying 0.02 0.03 1e-6\n2 kneading 0.0 0.01 1e-6\n",
                {"line 2", "must be sorted", "zone 1 (line 1)"}},
        BadCase{"overlapping", "1 conveying 0.0 0.02 1e-6\n# c\n2 kneading 0.015 0.03 1e-6\n",
                {"line 3", "overlaps zone 1 (line 1)", "ends at x = 0.02"}}),
    [](const ::testing::TestParamInfo<BadCase> &param) {
      std::string name = param.param.name;
      for (char &ch : name)
        if (ch == ' ') ch = '_';
      return name;
    });

TEST(ZonesFile, CheckInsideNamesTheZoneAndTheBox) {
  const auto zones = parse_zones_text(kGenerated, "zones.txt");
  EXPECT_NO_THROW(tsg::zones::check_inside(zones, 0.0, 0.06, "zones.txt"));
  try {
    tsg::zones::check_inside(zones, 0.0, 0.055, "zones.txt");
    FAIL() << "no error";
  } catch (const std::invalid_argument &e) {
    const std::string message = e.what();
    EXPECT_NE(message.find("line 8"), std::string::npos) << message;
    EXPECT_NE(message.find("zone 4 [0.05, 0.06]"), std::string::npos) << message;
    EXPECT_NE(message.find("[0, 0.055]"), std::string::npos) << message;
  }
  EXPECT_THROW(tsg::zones::check_inside(zones, 0.001, 0.06, "zones.txt"), std::invalid_argument);
}

TEST(ZonesFile, FindZoneIsHalfOpenAndKnowsGaps) {
  const auto zones = parse_zones_text(kGenerated, "zones.txt");
  EXPECT_EQ(find_zone(zones, -1e-9), -1);
  EXPECT_EQ(find_zone(zones, 0.0), 0);
  EXPECT_EQ(find_zone(zones, 0.01), 0);
  EXPECT_EQ(find_zone(zones, 2.9166666667e-02), 1);  // a boundary belongs to the zone it starts
  EXPECT_EQ(find_zone(zones, 0.04), 2);
  EXPECT_EQ(find_zone(zones, 0.045), -1);            // the gap between zones 3 and 4
  EXPECT_EQ(find_zone(zones, 0.05), 3);
  EXPECT_EQ(find_zone(zones, 0.06), -1);             // x_end is outside
}

}  // namespace
