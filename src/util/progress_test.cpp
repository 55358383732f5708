// The progress bar counts work from many threads and ends its line; one never advanced prints
// nothing.
#include "util/progress.h"

#include <gtest/gtest.h>
#include <tbb/parallel_for.h>

#include <sstream>

#include "util/memory.h"

namespace radiosa {

TEST(ProgressBar, CountsFromManyThreadsAndEndsItsLine) {
    std::ostringstream out;
    {
        ProgressBar bar(&out, "pairs", 1000);
        tbb::parallel_for(0, 1000, [&](int) { bar.add(1); });
    }
    const std::string s = out.str();
    ASSERT_FALSE(s.empty());
    EXPECT_EQ(s.front(), '\r');
    EXPECT_EQ(s.back(), '\n');
    // The last line drawn (by the destructor) is the whole of the work.
    const std::string last = s.substr(s.rfind('\r'));
    EXPECT_NE(last.find("pairs [##############################] 100%"), std::string::npos) << last;
}

TEST(ProgressBar, ABarNeverAdvancedLeavesNoLine) {
    // A stage that finished at once (or was skipped) must not leave an empty bar behind.
    std::ostringstream out;
    { ProgressBar bar(&out, "pairs", 10); }
    EXPECT_EQ(out.str(), "");
}

TEST(PeakMemory, IsAtLeastWhatWasTouched) {
    std::vector<char> block(64 << 20, 1);  // 64 MB, written
    EXPECT_GE(peak_memory_mb(), 64.0);
    EXPECT_EQ(block[12345], 1);
}

}  // namespace radiosa
