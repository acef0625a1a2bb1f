// Unit tests of the zones-file parser and look-ups (src-liggghts-eepa/physics/zones.h).
#include <gtest/gtest.h>

#include <cstdint>
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
std::string error_of(const std::string &text)
{
  try {
    parse_zones_text(text, "zones.txt");
  } catch (const std::invalid_argument &e) {
    return e.what();
  }
  return "";
}

TEST(ZonesFile, ParsesTheGeneratorFormat)
{
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

TEST(ZonesFile, AcceptsWindowsLineEndings)
{
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

TEST_P(BadZonesFile, NamesTheLineAndTheReason)
{
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
        BadCase{"index out of sequence",
                "1 conveying 0 0.01 1e-6\n3 kneading 0.01 0.02 1e-6\n",
                {"line 2", "index 3 out of sequence", "expected 2"}},
        BadCase{"unknown type", "1 mixing 0 0.01 1e-6\n", {"line 1", "type 'mixing'", "conveying, kneading, chopping"}},
        BadCase{"number with unit", "1 conveying 0 0.01m 1e-6\n", {"line 1", "x_end '0.01m'", "not a finite number"}},
        BadCase{"nan", "1 conveying nan 0.01 1e-6\n", {"line 1", "x_start 'nan'", nullptr}},
        BadCase{"empty zone",
                "1 conveying 0.01 0.01 1e-6\n",
                {"line 1", "x_end 0.01 must be greater than x_start", nullptr}},
        BadCase{"reversed zone", "1 conveying 0.02 0.01 1e-6\n", {"line 1", "greater than x_start 0.02", nullptr}},
        BadCase{"zero free volume", "1 conveying 0 0.01 0\n", {"line 1", "free_volume 0 must be positive", nullptr}},
        BadCase{"negative free volume", "1 conveying 0 0.01 -1e-6\n", {"line 1", "must be positive", nullptr}},
        BadCase{"unsorted",
                "1 conveying 0.02 0.03 1e-6\n2 kneading 0.0 0.01 1e-6\n",
                {"line 2", "must be sorted", "zone 1 (line 1)"}},
        BadCase{"overlapping",
                "1 conveying 0.0 0.02 1e-6\n# c\n2 kneading 0.015 0.03 1e-6\n",
                {"line 3", "overlaps zone 1 (line 1)", "ends at x = 0.02"}}),
    [](const ::testing::TestParamInfo<BadCase> &param) {
      std::string name = param.param.name;
      for (char &ch : name)
        if (ch == ' ') ch = '_';
      return name;
    });

TEST(ZonesFile, CheckInsideNamesTheZoneAndTheBox)
{
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

TEST(ZonesFile, FindZoneIsHalfOpenAndKnowsGaps)
{
  const auto zones = parse_zones_text(kGenerated, "zones.txt");
  EXPECT_EQ(find_zone(zones, -1e-9), -1);
  EXPECT_EQ(find_zone(zones, 0.0), 0);
  EXPECT_EQ(find_zone(zones, 0.01), 0);
  EXPECT_EQ(find_zone(zones, 2.9166666667e-02), 1);  // a boundary belongs to the zone it starts
  EXPECT_EQ(find_zone(zones, 0.04), 2);
  EXPECT_EQ(find_zone(zones, 0.045), -1);  // the gap between zones 3 and 4
  EXPECT_EQ(find_zone(zones, 0.05), 3);
  EXPECT_EQ(find_zone(zones, 0.06), -1);  // x_end is outside
}

}  // namespace

// ---- identity of a zone set (what a restart file keeps) ------------------------------------------

namespace {

const char *kFourZones =
    "1 conveying 0.01 0.03 2e-6\n2 kneading 0.03 0.04 1e-6\n3 chopping 0.05 0.07 2e-6\n4 kneading 0.07 0.08 1e-6\n";

}  // namespace

TEST(ZonesIdentity, SameZonesWrittenDifferentlyAreTheSame)
{
  // comments, blank lines and number formatting do not change what the zones are
  const auto a = tsg::zones::parse_zones_text(kFourZones, "a");
  const auto b = tsg::zones::parse_zones_text(
      "# regenerated\n1 conveying 1.0e-2 3.0e-2 2.0e-6\n\n2 kneading 0.030 0.040 0.000001\n"
      "3 chopping 5e-2 7e-2 2e-6\n4 kneading 0.07 0.08 1e-6\n",
      "b");
  const auto stored = tsg::zones::identity(a);
  ASSERT_EQ(stored.size(), 3u + 4u * 4u);
  EXPECT_EQ(tsg::zones::identity_size(stored.data()), stored.size());
  EXPECT_EQ(tsg::zones::identity_difference(stored.data(), b), "");
  EXPECT_EQ(tsg::zones::content_hash(a), tsg::zones::content_hash(b));
}

TEST(ZonesIdentity, HashHalvesAreExactInADouble)
{
  const auto zones = tsg::zones::parse_zones_text(kFourZones, "a");
  const auto stored = tsg::zones::identity(zones);
  const std::uint64_t hash = tsg::zones::content_hash(zones);
  EXPECT_EQ(static_cast<std::uint64_t>(stored[1]), hash >> 32);
  EXPECT_EQ(static_cast<std::uint64_t>(stored[2]), hash & 0xffffffffull);
}

TEST(ZonesIdentity, AShiftedZoneIsNamedWithBothValues)
{
  // the case of the issue: the same count, one boundary moved by 5 mm
  const auto before = tsg::zones::parse_zones_text(kFourZones, "a");
  const auto after = tsg::zones::parse_zones_text(
      "1 conveying 0.01 0.035 2e-6\n2 kneading 0.035 0.04 1e-6\n3 chopping 0.05 0.07 2e-6\n4 kneading 0.07 0.08 1e-6\n",
      "b");
  const std::string message = tsg::zones::identity_difference(tsg::zones::identity(before).data(), after);
  EXPECT_NE(message.find("zone 1 x_end: 0.03 in the restart file, 0.035 now"), std::string::npos) << message;
  EXPECT_NE(message.find("content hash " + tsg::zones::hash_text(tsg::zones::content_hash(before))), std::string::npos)
      << message;
  EXPECT_NE(tsg::zones::content_hash(before), tsg::zones::content_hash(after));
}

TEST(ZonesIdentity, CountTypeAndFreeVolumeDifferencesAreNamed)
{
  const auto base = tsg::zones::parse_zones_text(kFourZones, "a");
  const auto stored = tsg::zones::identity(base);
  const auto fewer = tsg::zones::parse_zones_text("1 conveying 0.01 0.03 2e-6\n", "b");
  EXPECT_EQ(tsg::zones::identity_difference(stored.data(), fewer).rfind("4 zones in the restart file, 1 now", 0), 0u);
  auto retyped = base;
  retyped[2].type = tsg::zones::ZoneType::kneading;
  EXPECT_NE(tsg::zones::identity_difference(stored.data(), retyped)
                .find("zone 3 type: chopping in the restart file, kneading now"),
            std::string::npos);
  auto volume = base;
  volume[3].free_volume = 1.5e-6;
  EXPECT_NE(tsg::zones::identity_difference(stored.data(), volume)
                .find("zone 4 free_volume: 1e-06 in the restart file, 1.5e-06 now"),
            std::string::npos);
}
