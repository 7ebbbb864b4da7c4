// apps/steps_page.h: the embedded page is byte-for-byte apps/steps_page/*, in the documented order.
#include "apps/steps_page.h"

#include <gtest/gtest.h>

#include <fstream>
#include <sstream>
#include <string>

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

} // namespace
