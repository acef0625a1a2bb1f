// Zones (screw elements) along the granulator axis: the zones file and look-ups, dependency-free.
//
// Zones file, written by the mesh generator (meshes/tsg_meshes/build.py, zones.txt):
//   - lines whose first non-blank character is '#' are comments; blank lines are ignored;
//   - one line per element:  index type x_start x_end free_volume
//       index        1, 2, 3, ... in file order
//       type         conveying | kneading | chopping
//       x_start/x_end axial extent in metres, x_start < x_end
//       free_volume  free (void) volume of the zone in m^3, > 0
//   - zones sorted by x_start and not overlapping (adjacent zones, x_end[i] == x_start[i+1], allowed).
// Axial direction is x (screw axes along +x, flow towards +x).
//
// Every violation throws std::invalid_argument with the source name, the line number and the reason.
#ifndef TSG_ZONES_H
#define TSG_ZONES_H

#include <cerrno>
#include <climits>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <istream>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "numbers.h"

namespace tsg::zones {

enum class ZoneType { conveying = 0, kneading = 1, chopping = 2 };
constexpr int kZoneTypes = 3;

// The zones file's type names, indexed by ZoneType: read, written and listed from this one table.
constexpr const char *kZoneTypeNames[kZoneTypes] = {"conveying", "kneading", "chopping"};

inline const char *type_name(ZoneType type) { return kZoneTypeNames[static_cast<int>(type)]; }

struct Zone {
  int index;  // 1-based, as in the file
  ZoneType type;
  double x_start;      // m
  double x_end;        // m
  double free_volume;  // m^3
  int line;            // line of the file it came from (for later error messages)
};

namespace detail {

inline std::string where(const std::string &source, int line)
{
  return source + ", line " + std::to_string(line) + ": ";
}

}  // namespace detail

// Parses a zones file from a stream; `source` names it in error messages (usually its path).
inline std::vector<Zone> parse_zones(std::istream &in, const std::string &source)
{
  using detail::where;
  std::vector<Zone> zones;
  std::string text;
  int line_number = 0;
  while (std::getline(in, text)) {
    ++line_number;
    if (!text.empty() && text.back() == '\r') text.pop_back();  // files written on Windows
    const auto first = text.find_first_not_of(" \t");
    if (first == std::string::npos || text[first] == '#') continue;
    std::istringstream fields(text);
    std::vector<std::string> tokens;
    for (std::string token; fields >> token;) tokens.push_back(token);
    if (tokens.size() != 5)
      throw std::invalid_argument(where(source, line_number) +
                                  "expected 5 fields 'index type x_start x_end free_volume', found " +
                                  std::to_string(tokens.size()) + " in '" + text + "'");
    Zone zone{};
    zone.line = line_number;
    long index = 0;
    if (!tsg::parse_integer(tokens[0].c_str(), LONG_MIN, LONG_MAX, index))
      throw std::invalid_argument(where(source, line_number) + "index '" + tokens[0] + "' is not an integer");
    const long expected = static_cast<long>(zones.size()) + 1;
    if (index != expected)
      throw std::invalid_argument(where(source, line_number) + "index " + tokens[0] + " out of sequence: expected " +
                                  std::to_string(expected) + " (zones are numbered 1, 2, 3, ... in file order)");
    zone.index = static_cast<int>(index);
    int type = 0;
    while (type < kZoneTypes && tokens[1] != kZoneTypeNames[type]) ++type;
    if (type == kZoneTypes)
      throw std::invalid_argument(where(source, line_number) + "type '" + tokens[1] + "' is not one of " +
                                  kZoneTypeNames[0] + ", " + kZoneTypeNames[1] + ", " + kZoneTypeNames[2]);
    zone.type = static_cast<ZoneType>(type);
    const char *names[3] = {"x_start", "x_end", "free_volume"};
    double *targets[3] = {&zone.x_start, &zone.x_end, &zone.free_volume};
    for (int k = 0; k < 3; ++k)
      if (!tsg::parse_real(tokens[2 + k].c_str(), *targets[k]))
        throw std::invalid_argument(where(source, line_number) + names[k] + " '" + tokens[2 + k] +
                                    "' is not a finite number");
    if (!(zone.x_end > zone.x_start))
      throw std::invalid_argument(where(source, line_number) + "x_end " + tokens[3] + " must be greater than x_start " +
                                  tokens[2]);
    if (!(zone.free_volume > 0))
      throw std::invalid_argument(where(source, line_number) + "free_volume " + tokens[4] + " must be positive (m^3)");
    if (!zones.empty()) {
      const Zone &previous = zones.back();
      if (zone.x_start < previous.x_start)
        throw std::invalid_argument(where(source, line_number) + "zone " + tokens[0] + " starts at x = " + tokens[2] +
                                    ", before zone " + std::to_string(previous.index) + " (line " +
                                    std::to_string(previous.line) + "): zones must be sorted by x_start");
      if (zone.x_start < previous.x_end)
        throw std::invalid_argument(
            where(source, line_number) + "zone " + tokens[0] + " [" + tokens[2] + ", " + tokens[3] +
            "] overlaps zone " + std::to_string(previous.index) + " (line " + std::to_string(previous.line) +
            ") which ends at x = " + tsg::number(previous.x_end) + " (adjacent zones may touch, not overlap)");
    }
    zones.push_back(zone);
  }
  if (in.bad()) throw std::invalid_argument(source + ": read error");
  if (zones.empty())
    throw std::invalid_argument(source + ": no zones (expected lines 'index type x_start x_end free_volume')");
  return zones;
}

inline std::vector<Zone> parse_zones_text(const std::string &text, const std::string &source)
{
  std::istringstream in(text);
  return parse_zones(in, source);
}

// Throws unless every zone lies inside [lo, hi] (the simulation box along x).
inline void check_inside(const std::vector<Zone> &zones, double lo, double hi, const std::string &source)
{
  for (const Zone &zone : zones)
    if (zone.x_start < lo || zone.x_end > hi) {
      std::ostringstream message;
      message.precision(10);
      message << detail::where(source, zone.line) << "zone " << zone.index << " [" << zone.x_start << ", " << zone.x_end
              << "] lies (partly) outside the simulation box along x [" << lo << ", " << hi << "]";
      throw std::invalid_argument(message.str());
    }
}

// Index (0-based) of the zone containing x, half-open [x_start, x_end); -1 when none does.
inline int find_zone(const std::vector<Zone> &zones, double x)
{
  std::size_t lo = 0, hi = zones.size();
  while (lo < hi) {  // first zone with x_end > x
    const std::size_t mid = (lo + hi) / 2;
    if (zones[mid].x_end > x)
      hi = mid;
    else
      lo = mid + 1;
  }
  if (lo < zones.size() && zones[lo].x_start <= x) return static_cast<int>(lo);
  return -1;
}

// First zone (0-based) whose x_end is greater than x; zones.size() when none.
inline std::size_t first_zone_ending_after(const std::vector<Zone> &zones, double x)
{
  std::size_t lo = 0, hi = zones.size();
  while (lo < hi) {
    const std::size_t mid = (lo + hi) / 2;
    if (zones[mid].x_end > x)
      hi = mid;
    else
      lo = mid + 1;
  }
  return lo;
}

// ---- identity of a zone set (restart files) -------------------------------------------------------
// A restart must continue with the zones it was written with: cells of two zone sets must not mix.
// identity() lists what defines the set: {count, content hash (high, low 32 bits), then per zone
// type, x_start, x_end, free_volume}; the content hash is 64-bit FNV-1a over the bytes of those values
// (comments and number formatting in the file do not change it). All entries are exact in a double.
constexpr int kIdentityHead = 3;
constexpr int kIdentityPerZone = 4;

inline std::uint64_t content_hash(const std::vector<Zone> &zones)
{
  std::uint64_t hash = 14695981039346656037ull;  // FNV-1a offset basis and prime (64 bit)
  auto mix = [&hash](double value) {
    unsigned char bytes[sizeof value];
    std::memcpy(bytes, &value, sizeof value);
    for (unsigned char byte : bytes) {
      hash ^= byte;
      hash *= 1099511628211ull;
    }
  };
  for (const Zone &zone : zones) {
    mix(static_cast<double>(zone.type));
    mix(zone.x_start);
    mix(zone.x_end);
    mix(zone.free_volume);
  }
  return hash;
}

inline std::string hash_text(std::uint64_t hash)
{
  char text[17];
  std::snprintf(text, sizeof text, "%016llx", static_cast<unsigned long long>(hash));
  return text;
}

inline std::vector<double> identity(const std::vector<Zone> &zones)
{
  const std::uint64_t hash = content_hash(zones);
  std::vector<double> out{static_cast<double>(zones.size()), static_cast<double>(hash >> 32),
                          static_cast<double>(hash & 0xffffffffull)};
  for (const Zone &zone : zones)
    out.insert(out.end(), {static_cast<double>(zone.type), zone.x_start, zone.x_end, zone.free_volume});
  return out;
}

inline std::size_t identity_size(const double *stored)
{
  return kIdentityHead + kIdentityPerZone * static_cast<std::size_t>(stored[0]);
}

// "" when `stored` (an identity() written earlier) describes `zones`; otherwise what differs first,
// e.g. "zone 2 x_start: 0.03 in the restart file, 0.035 now".
inline std::string identity_difference(const double *stored, const std::vector<Zone> &zones)
{
  using tsg::number;
  const std::vector<double> now = identity(zones);
  const std::size_t count = static_cast<std::size_t>(stored[0]);
  const std::uint64_t stored_hash =
      (static_cast<std::uint64_t>(stored[1]) << 32) | static_cast<std::uint64_t>(stored[2]);
  const std::string hashes =
      " (content hash " + hash_text(stored_hash) + " in the restart file, " + hash_text(content_hash(zones)) + " now)";
  if (count != zones.size())
    return std::to_string(count) + " zones in the restart file, " + std::to_string(zones.size()) + " now" + hashes;
  const char *fields[kIdentityPerZone] = {"type", "x_start", "x_end", "free_volume"};
  for (std::size_t z = 0; z < count; ++z)
    for (int f = 0; f < kIdentityPerZone; ++f) {
      const std::size_t k = kIdentityHead + kIdentityPerZone * z + static_cast<std::size_t>(f);
      if (std::memcmp(&stored[k], &now[k], sizeof(double)) == 0) continue;
      const auto show = [f](double value) {
        return f == 0 ? std::string(type_name(static_cast<ZoneType>(static_cast<int>(value)))) : number(value);
      };
      return "zone " + std::to_string(z + 1) + " " + fields[f] + ": " + show(stored[k]) + " in the restart file, " +
             show(now[k]) + " now" + hashes;
    }
  if (stored[1] != now[1] || stored[2] != now[2]) return "the content hashes differ" + hashes;
  return "";
}

}  // namespace tsg::zones

#endif
