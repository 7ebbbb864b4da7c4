// apps/render_request.h: `focal render`'s lens options as the library's LensRequest, and the
// library's field names in messages mapped back to the options, so the command line still names
// what the user typed (checked on the messages of `focal render` run as a child process).
#include "apps/render_request.h"
#include "apps/settings_options.h"
#include "support/subprocess.h"

#include <gtest/gtest.h>

#include <string>
#include <vector>

namespace focal::test {
namespace {

TEST(RenderRequest, LensFieldsBecomeOptionsInMessages) {
    EXPECT_EQ(withOptionNames("aperture_radius must be a finite number >= 0, got -1.000000"),
              "--aperture-radius must be a finite number >= 0, got -1.000000");
    EXPECT_EQ(withOptionNames("fstop needs focal_length_mm"), "--fstop needs --focal-length");
    EXPECT_EQ(withOptionNames("sensor_height_mm, focus_distance and focus_pixel"),
              "--sensor-height, --focus-distance and --focus-pixel");
    // Whole identifiers only; other text is kept as it is.
    EXPECT_EQ(withOptionNames("fstops focus_pixels focus distance (x_fstop)"),
              "fstops focus_pixels focus distance (x_fstop)");
    EXPECT_EQ(withOptionNames(""), "");
}

TEST(RenderRequest, OptionsFillTheLensRequest) {
    RenderArgs args;
    args.fstop = 2.8f;
    args.focal_length_mm = 50.0f;
    args.focus_pixel = "12,34";
    args.eye = "0,0,5";
    args.method = "gather";
    raster::Result<dof::LensRequest> r = lensRequestOf(args);
    ASSERT_TRUE(r.ok()) << r.status().message();
    EXPECT_EQ(r->fstop, 2.8f);
    EXPECT_EQ(r->focal_length_mm, 50.0f);
    EXPECT_FALSE(r->aperture_radius.has_value());
    ASSERT_TRUE(r->focus_pixel.has_value());
    EXPECT_EQ(*r->focus_pixel, glm::uvec2(12, 34));
    EXPECT_TRUE(r->view_focus);     // --eye/--target: the target's distance
    EXPECT_FALSE(r->pinhole_image); // gather uses the lens
    args.focus_pixel = "1;2";
    r = lensRequestOf(args);
    ASSERT_FALSE(r.ok());
    EXPECT_NE(r.status().message().find("--focus-pixel"), std::string::npos);
}

TEST(RenderRequest, CommandLineLensErrorsNameTheOption) {
    const std::vector<std::pair<std::vector<std::string>, std::string>> cases = {
        {{"--aperture-radius", "-1"}, "--aperture-radius"},
        {{"--fstop", "0", "--focal-length", "50"}, "--fstop"},
        {{"--focus-distance", "0"}, "--focus-distance"},
        {{"--focus-pixel", "0,0"}, "--focus-pixel"},   // sky: nothing to focus on
        {{"--focus-pixel", "500,5"}, "--focus-pixel"}, // outside the image
        {{"--focus-distance", "1e9"}, "far plane"},
    };
    for (const auto& [extra, expected] : cases) {
        std::vector<std::string> argv = {
            FOCAL_BINARY, "render", "builtin:demo", "-o",    "/nonexistent/x.exr", "--width", "48",
            "--height",   "36",     "--method",     "gather"};
        argv.insert(argv.end(), extra.begin(), extra.end());
        const ProcessResult r = runProcess(argv);
        EXPECT_EQ(r.exit_code, 1) << r.err;
        EXPECT_NE(r.err.find(expected), std::string::npos) << r.err;
        EXPECT_EQ(r.err.find("focus_pixel"), std::string::npos) << r.err;
        EXPECT_EQ(r.err.find("aperture_radius"), std::string::npos) << r.err;
    }
}

} // namespace
} // namespace focal::test
