// The residence ledger: the bookkeeping that guarantees that no tracked particle vanishes without a
// record, dependency-free (the MPI exchange of ids stays in fix residence/time).
//
// Each rank keeps a copy ("shadow") of the state of every inside particle it owns, keyed by particle
// id and refreshed whenever that state changes. Particles leave a rank in three ways:
//   - migration: packed for another rank (pack_exchange). The entry is marked "in transit" and the
//     pack is counted; the receiving rank counts an arrival and remembers the particle itself;
//   - deletion (delete_atoms, a deleting fix): the entry is neither in transit nor owned any more;
//   - loss (left a non-periodic box with thermo_modify lost ignore): packed, but, over all ranks,
//     fewer arrivals than packs; the ids in transit that no rank owns were lost.
// reconcile steps (on reneighbouring steps and at set-up): take_deleted() with the ids owned now,
// then, if the global pack gap is not zero, match transit_ids() across ranks, then end_exchange().
#ifndef TSG_LEDGER_H
#define TSG_LEDGER_H

#include <algorithm>
#include <unordered_map>
#include <unordered_set>
#include <utility>
#include <vector>

namespace tsg::residence {

class Ledger {
public:
  using Id = long long;

  // Particle `id`, owned here and inside, has this state now (added, refreshed, or back from transit).
  void remember(Id id, const double *state, int size)
  {
    auto it = entries_.find(id);
    if (it == entries_.end()) {
      entries_.emplace(id, Entry{std::vector<double>(state, state + size), false});
      return;
    }
    if (it->second.transit) --transit_;
    it->second.state.assign(state, state + size);
    it->second.transit = false;
  }

  // Particle `id` is no longer inside (its residence ended with a record here).
  void forget(Id id)
  {
    auto it = entries_.find(id);
    if (it == entries_.end()) return;
    if (it->second.transit) --transit_;
    entries_.erase(it);
  }

  // An inside particle was packed for another rank.
  void packed(Id id)
  {
    ++packs_;
    auto it = entries_.find(id);
    if (it != entries_.end() && !it->second.transit) {
      it->second.transit = true;
      ++transit_;
    }
  }

  // An inside particle arrived from another rank (remember() it as well).
  void arrived() { ++arrivals_; }

  // Entries owned here and not in transit.
  long resident() const { return static_cast<long>(entries_.size()) - transit_; }
  long packs_minus_arrivals() const { return packs_ - arrivals_; }

  // Whether `id` is held as resident (owned here, not in transit).
  bool holds(Id id) const
  {
    auto it = entries_.find(id);
    return it != entries_.end() && !it->second.transit;
  }

  // Removes and returns, sorted by id, the resident entries whose particle is not in `owned` (the
  // ids of the inside particles owned here now): they were deleted.
  std::vector<std::pair<Id, std::vector<double>>> take_deleted(const std::unordered_set<Id> &owned)
  {
    std::vector<Id> gone;
    for (const auto &entry : entries_)
      if (!entry.second.transit && !owned.count(entry.first)) gone.push_back(entry.first);
    std::sort(gone.begin(), gone.end());
    std::vector<std::pair<Id, std::vector<double>>> out;
    out.reserve(gone.size());
    for (Id id : gone) {
      out.emplace_back(id, std::move(entries_[id].state));
      entries_.erase(id);
    }
    return out;
  }

  // Ids in transit from here (unsorted).
  std::vector<Id> transit_ids() const
  {
    std::vector<Id> ids;
    for (const auto &entry : entries_)
      if (entry.second.transit) ids.push_back(entry.first);
    return ids;
  }

  // For the loss search: my claim on `id` — `me` if it is in transit from here, -1 if I own it
  // (resident here: it arrived, so it is not lost), `nobody` if I know nothing of it. The lowest
  // claim over all ranks decides: -1 means owned somewhere, a rank number means lost, recorded by
  // that rank (the lowest one holding it in transit).
  int claim(Id id, int me, int nobody) const
  {
    auto it = entries_.find(id);
    if (it == entries_.end()) return nobody;
    return it->second.transit ? me : -1;
  }

  // The state of an entry (nullptr when none).
  const std::vector<double> *state(Id id) const
  {
    auto it = entries_.find(id);
    return it == entries_.end() ? nullptr : &it->second.state;
  }

  // After a reconcile: entries still in transit arrived elsewhere (or were recorded as lost).
  void end_exchange()
  {
    if (transit_ > 0)
      for (auto it = entries_.begin(); it != entries_.end();) {
        if (it->second.transit)
          it = entries_.erase(it);
        else
          ++it;
      }
    transit_ = 0;
    packs_ = arrivals_ = 0;
  }

  std::size_t size() const { return entries_.size(); }

private:
  struct Entry {
    std::vector<double> state;
    bool transit;
  };
  std::unordered_map<Id, Entry> entries_;
  long transit_ = 0;
  long packs_ = 0, arrivals_ = 0;
};

}  // namespace tsg::residence

#endif
