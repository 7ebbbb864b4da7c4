// apps/steps_page.h: the embedded page is byte-for-byte apps/steps_page/*, in the documented order,
// and writeStepsPage writes it into a folder.
#include "apps/steps_page.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <unistd.h>

namespace {

std::string readSource(const std::string& name) {
    std::ifstream in(std::string(FOCAL_SOURCE_DIR) + "/apps/steps_page/" + name, std::ios::binary);
    std::ostringstream text;
    text << in.rdbuf();
    return text.str();
}

TEST(StepsPage, EmbedsTheThreePageFilesUnchanged) {
    const auto files = focal::stepsPageFiles();
    ASSERT_EQ(files.size(), 3u);
    const char* names[] = {"index.html", "steps.css", "steps.js"};
    for (size_t i = 0; i < files.size(); ++i) {
        EXPECT_STREQ(files[i].name, names[i]);
        const std::string source = readSource(names[i]);
        ASSERT_FALSE(source.empty()) << names[i];
        EXPECT_EQ(files[i].content, source) << names[i] << " differs from apps/steps_page";
    }
}

TEST(StepsPage, WritesThePageIntoAFolder) {
    const std::filesystem::path dir = std::filesystem::temp_directory_path() /
                                      ("focal_steps_page_test_" + std::to_string(::getpid()));
    std::filesystem::create_directories(dir);
    ASSERT_TRUE(focal::writeStepsPage(dir.string()).ok());
    for (const focal::StepsPageFile& file : focal::stepsPageFiles()) {
        std::ifstream in(dir / file.name, std::ios::binary);
        std::ostringstream text;
        text << in.rdbuf();
        EXPECT_EQ(text.str(), file.content) << file.name;
    }
    EXPECT_FALSE(focal::writeStepsPage((dir / "missing" / "folder").string()).ok());
    std::filesystem::remove_all(dir);
}

} // namespace
