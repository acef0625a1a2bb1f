// Unit tests of common/record_rollback.h: the records a killed job wrote after its last restart file
// are dropped before the continued run appends.
#include <gtest/gtest.h>

#include <sstream>
#include <string>

#include "record_rollback.h"

namespace {

std::string kept(const std::string &text, int column, double limit, std::size_t *dropped)
{
  std::istringstream in(text);
  std::ostringstream out;
  *dropped = tsg::keep_records_until(in, out, column, limit);
  return out.str();
}

TEST(RecordRollback, MassFlowRowsAfterTheRestartTimeAreDropped)
{
  // massflow.txt: step time rate...; the restart was written at step 400 (t = 0.002)
  const std::string head = "# tsg-dem mass flow v1\n# window 200 steps\n";
  const std::string before = "200 0.001 4.5 3.9\n400 0.002 4.1 4.0\n";
  const std::string after = "600 0.003 4.2 4.4\n800 0.004 3.8 4.1\n";
  std::size_t dropped = 0;
  EXPECT_EQ(kept(head + before + after, 2, 0.002 + 0.5e-5, &dropped), head + before);
  EXPECT_EQ(dropped, 2u);
}

TEST(RecordRollback, ResidenceRecordsAreJudgedByTheirExitTime)
{
  // residence.txt: id entry_time exit_time ...; an early entry with a late exit goes, a late entry
  // cannot be kept without its exit
  const std::string text = "# columns: id entry_time exit_time residence_time exit_reason\n"
                           "7 0.0001 0.0019 0.0018 pass\n"
                           "9 0.0001 0.0031 0.0030 pass\n"
                           "3 0.0015 0.0020 0.0005 outlet\n";
  std::size_t dropped = 0;
  EXPECT_EQ(kept(text, 3, 0.002, &dropped),
            "# columns: id entry_time exit_time residence_time exit_reason\n7 0.0001 0.0019 0.0018 pass\n"
            "3 0.0015 0.0020 0.0005 outlet\n");
  EXPECT_EQ(dropped, 1u);
}

TEST(RecordRollback, NothingAfterTheLimitKeepsTheTextAndLinesWithoutATimeStay)
{
  const std::string text = "# h\n\n1 0.5\nshort\n2 x\n";
  std::size_t dropped = 7;
  EXPECT_EQ(kept(text, 2, 1.0, &dropped), text);
  EXPECT_EQ(dropped, 0u);
  // whitespace of any width separates columns; a number with trailing text is not a time
  EXPECT_EQ(kept("1 \t 2.5\n1 2.5x\n", 2, 1.0, &dropped), "1 2.5x\n");
  EXPECT_EQ(dropped, 1u);
}

}  // namespace
