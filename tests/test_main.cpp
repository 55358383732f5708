// The test binary's main: every test starts with a fresh, empty form-factor cache directory of
// its own (RADIOSA_CACHE_DIR, inherited by the radiosa processes tests start), so a local run
// is as cold, and as strict, as CI's fresh clone. Tests of warm behaviour make their own
// directory and fill it on purpose.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <string>

namespace {

class FreshCachePerTest : public ::testing::EmptyTestEventListener {
    void OnTestStart(const ::testing::TestInfo& info) override {
        m_dir = std::filesystem::temp_directory_path() / ("radiosa-test-cache-" + std::to_string(::getpid()) +
                                                          "-" + info.test_suite_name() + "." + info.name());
        std::filesystem::remove_all(m_dir);
        ::setenv("RADIOSA_CACHE_DIR", m_dir.c_str(), 1);
    }
    void OnTestEnd(const ::testing::TestInfo&) override {
        std::error_code ec;
        std::filesystem::remove_all(m_dir, ec);
    }
    std::filesystem::path m_dir;
};

}  // namespace

int main(int argc, char** argv) {
    ::testing::InitGoogleTest(&argc, argv);
    ::testing::UnitTest::GetInstance()->listeners().Append(new FreshCachePerTest);
    return RUN_ALL_TESTS();
}
