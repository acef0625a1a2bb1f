// `check_variables` — stop the run if a variable given on the command line (`lmp -var NAME VALUE`)
// was neither declared nor used by any input line read so far. Upstream ignores such a variable,
// so a misspelt name (`-var rmp 300`) ran with the input's default silently. Place it after the
// includes that declare the variables and before the first run; the error lists the declared
// names closest to each unclaimed one.
#ifdef COMMAND_CLASS
CommandStyle(check_variables, CheckVariablesCommand)
#else
#ifndef TSG_COMMAND_CHECK_VARIABLES_H
#define TSG_COMMAND_CHECK_VARIABLES_H

#include <algorithm>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "error.h"
#include "input.h"
#include "pointers.h"
#include "variable.h"

namespace tsg {

// Optimal string alignment distance (Damerau-Levenshtein without repeated edits of a substring):
// the fewest insertions, deletions, substitutions and swaps of two adjacent characters that turn a
// into b, so the typical typo "rmp" for "rpm" is 1.
inline std::size_t edit_distance(const std::string &a, const std::string &b)
{
  std::vector<std::vector<std::size_t>> d(a.size() + 1, std::vector<std::size_t>(b.size() + 1));
  for (std::size_t i = 0; i <= a.size(); ++i) d[i][0] = i;
  for (std::size_t j = 0; j <= b.size(); ++j) d[0][j] = j;
  for (std::size_t i = 1; i <= a.size(); ++i)
    for (std::size_t j = 1; j <= b.size(); ++j) {
      d[i][j] = std::min({d[i - 1][j] + 1, d[i][j - 1] + 1, d[i - 1][j - 1] + (a[i - 1] == b[j - 1] ? 0 : 1)});
      if (i > 1 && j > 1 && a[i - 1] == b[j - 2] && a[i - 2] == b[j - 1])
        d[i][j] = std::min(d[i][j], d[i - 2][j - 2] + 1);
    }
  return d[a.size()][b.size()];
}

// The candidates within edit distance max(2, |name|/3) of name, or of which name is a part cut
// short ("rho" for "rho_p", "feed_rate" for "feed_rate_kg_h", ranked as one edit), closest first
// (at most 5).
inline std::vector<std::string> close_names(const std::string &name, const std::vector<std::string> &candidates)
{
  const std::size_t limit = std::max<std::size_t>(2, name.size() / 3);
  std::vector<std::pair<std::size_t, std::string>> ranked;
  for (const std::string &c : candidates) {
    const std::size_t d = c.compare(0, name.size(), name) == 0 ? 1 : edit_distance(name, c);
    if (d <= limit) ranked.emplace_back(d, c);
  }
  std::sort(ranked.begin(), ranked.end());
  std::vector<std::string> out;
  for (std::size_t i = 0; i < ranked.size() && i < 5; ++i) out.push_back(ranked[i].second);
  return out;
}

}  // namespace tsg

namespace LAMMPS_NS {

class CheckVariablesCommand : protected Pointers {
public:
  explicit CheckVariablesCommand(class LAMMPS *lmp) : Pointers(lmp) {}
  void command(int narg, char ** /*arg*/)
  {
    if (narg != 0) error->all(FLERR, "check_variables takes no arguments");
    const std::set<std::string> &unclaimed = input->variable->unclaimed_command_line;
    if (unclaimed.empty()) return;
    std::vector<std::string> declared;
    for (const std::string &n : input->variable->defined_names())
      if (!unclaimed.count(n)) declared.push_back(n);
    std::string message = "check_variables:";
    for (const std::string &name : unclaimed) {
      message += (message.back() == ':' ? " -var " : "; -var ") + name + " names no variable of the input (";
      const std::vector<std::string> close = tsg::close_names(name, declared);
      if (close.empty()) message += "no declared name is close";
      for (std::size_t i = 0; i < close.size(); ++i) message += (i ? ", " : "did you mean ") + close[i];
      message += ")";
    }
    error->all(FLERR, message.c_str());
  }
};

}  // namespace LAMMPS_NS

#endif
#endif
