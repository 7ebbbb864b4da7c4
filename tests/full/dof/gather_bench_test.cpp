// Measurements of the gather method (dof/gather.h) for docs/dof/gather.md and docs/benchmarks.md:
// error against cached accum references on every built-in scene (16- and 32-bit depth), a focus
// pull (per-frame CoC error and frame-to-frame flicker of quantised depth), and the filter cost
// against the maximum radius. Heavy, so it runs only when FOCAL_GATHER_BENCH names a folder
// holding the references (ref/NAME.exr, written by the command in docs/dof/gather.md); results
// are printed as Markdown table rows.
#include "apps/image_io.h"
#include "support/test_util.h"

#include <dof/gather.h>
#include <dof/lens.h>
#include <dof/metrics.h>
#include <raster/camera.h>
#include <raster/renderer.h>
#include <raster/task_pool.h>
#include <scenes/builtin.h>

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>

namespace focal::test {
namespace {

const char* benchDir() {
    return std::getenv("FOCAL_GATHER_BENCH");
}

struct BenchScene {
    raster::Scene scene;
    raster::View view;
    dof::ThinLens lens;
};

BenchScene setupOf(const std::string& name, uint32_t w, uint32_t h) {
    raster::Result<raster::Scene> s = scenes::makeBuiltinScene(name);
    EXPECT_TRUE(s.ok());
    BenchScene st{std::move(*s), {}, {}};
    st.view = raster::viewFromCamera(st.scene.cameras[0], w, h);
    st.view.focus_distance = st.scene.lens->focus_distance;
    st.lens =
        dof::makeThinLens(st.view, st.scene.lens->aperture_radius, st.scene.lens->focus_distance);
    return st;
}

raster::Frame renderPinhole(const BenchScene& st, raster::DepthFormat fmt) {
    raster::RenderOptions opt;
    opt.depth_format = fmt;
    return render(st.scene, st.view, opt, 2);
}

dof::GatherImage imageOf(const raster::Frame& f) {
    return {f.color.data(), dof::depthRefOf(f.depth), f.width, f.height};
}

struct Timed {
    dof::GatherStats stats;
    double ms = 1e30; // best of the runs: coc + vertical + horizontal
};

Timed runGather(const raster::Frame& f, const BenchScene& st, const dof::GatherSettings& s,
                std::vector<float>& out, std::vector<float>* coc = nullptr, int runs = 3) {
    Timed t;
    dof::GatherScratch scratch;
    for (int i = 0; i < runs; ++i) {
        raster::Result<dof::GatherStats> r =
            dof::gather(imageOf(f), st.lens, st.view, s, out, coc, nullptr, &scratch);
        EXPECT_TRUE(r.ok()) << r.status().message();
        const double ms = r->ms_coc + r->ms_vertical + r->ms_horizontal;
        if (ms < t.ms) {
            t.ms = ms;
            t.stats = *r;
        }
    }
    return t;
}

std::string fmt(double v, const char* f = "%.2f") {
    char buf[64];
    std::snprintf(buf, sizeof buf, f, v);
    return buf;
}

TEST(GatherBench, ErrorAgainstAccumOnEveryBuiltinScene) {
    if (!benchDir())
        GTEST_SKIP() << "set FOCAL_GATHER_BENCH to the folder with ref/NAME.exr";
    const std::string dir = benchDir();
    std::printf("| scene | depth | filter ms | PSNR dB | SSIM | band PSNR dB | band SSIM | "
                "pinhole PSNR / band | max |C| px | tiles copied |\n");
    for (const scenes::BuiltinInfo& info : scenes::builtinScenes()) {
        const std::string name(info.name);
        raster::Result<ImageData> ref = readImage(dir + "/ref/" + name + ".exr");
        if (!ref.ok()) {
            std::printf("| %s | no reference |\n", name.c_str());
            continue;
        }
        const BenchScene st = setupOf(name, ref->width, ref->height);
        const dof::ImageRef ref_img{ref->pixels.data(), ref->width, ref->height, ref->channels};
        for (raster::DepthFormat df :
             {raster::DepthFormat::Float32, raster::DepthFormat::Unorm16}) {
            const raster::Frame pin = renderPinhole(st, df);
            std::vector<float> depth(size_t(pin.width) * pin.height);
            for (size_t i = 0; i < depth.size(); ++i)
                depth[i] = raster::distanceFromDepth(st.view, pin.depth.load(i));
            const std::vector<uint8_t> band =
                dof::discontinuityBand({depth.data(), pin.width, pin.height, 1}, 0.05f, 4.0f);
            std::vector<float> out;
            const Timed t = runGather(pin, st, {}, out);
            const dof::ImageRef out_img{out.data(), pin.width, pin.height, 4};
            const dof::ImageRef pin_img{pin.color.data(), pin.width, pin.height, 4};
            const auto full = dof::compareImages(ref_img, out_img);
            const auto edge = dof::compareImages(ref_img, out_img, &band);
            const auto pfull = dof::compareImages(ref_img, pin_img);
            const auto pedge = dof::compareImages(ref_img, pin_img, &band);
            ASSERT_TRUE(full.ok() && edge.ok() && pfull.ok() && pedge.ok());
            const bool f32 = df == raster::DepthFormat::Float32;
            std::printf(
                "| %s | %s | %s | %s | %s | %s | %s | %s / %s | %s | %u/%u |\n", name.c_str(),
                f32 ? "float32" : "unorm16", fmt(t.ms).c_str(), fmt(full->psnr_srgb_db).c_str(),
                fmt(full->ssim, "%.4f").c_str(), fmt(edge->psnr_srgb_db).c_str(),
                fmt(edge->ssim, "%.4f").c_str(), fmt(pfull->psnr_srgb_db).c_str(),
                fmt(pedge->psnr_srgb_db).c_str(),
                fmt(std::max(std::fabs(t.stats.min_coc_px), std::fabs(t.stats.max_coc_px)), "%.1f")
                    .c_str(),
                t.stats.tiles_copied, t.stats.tiles);
            if (f32) {
                ImageData img{pin.width, pin.height, 4, out};
                EXPECT_TRUE(writeImage(dir + "/gather_" + name + ".png", img).ok());
                ImageData diff{pin.width, pin.height, 3,
                               dof::falseColorDifference(ref_img, out_img, 0.1f)};
                EXPECT_TRUE(writeImage(dir + "/gather_" + name + "_diff.png", diff).ok());
                ImageData refpng{ref->width, ref->height, ref->channels, ref->pixels};
                EXPECT_TRUE(writeImage(dir + "/accum_" + name + ".png", refpng).ok());
            }
        }
    }
}

// The focus pull: d_f sweeps uniformly in 1/d_f (the CoC is affine in 1/d_f) over `frames`
// frames. The pinhole is rendered once per depth format (the depth buffer does not depend on
// the lens); the float32 buffer is the reference. "unorm8" re-quantises the float32 D to 8 bits,
// as the paper's 8-bit alpha channel would (§5).
TEST(GatherBench, FocusPullPopping) {
    if (!benchDir())
        GTEST_SKIP() << "set FOCAL_GATHER_BENCH";
    constexpr uint32_t kW = 320, kH = 240, kFrames = 48;
    BenchScene st = setupOf("demo", kW, kH);
    const float aperture = st.lens.aperture_radius;
    const raster::Frame f32 = renderPinhole(st, raster::DepthFormat::Float32);
    const raster::Frame f16 = renderPinhole(st, raster::DepthFormat::Unorm16);
    raster::Frame f8 = f32;
    for (float& d : f8.depth.float32)
        d = std::round(d * 255.0f) / 255.0f;
    struct Acc {
        double coc_mean = 0, coc_max = 0, flick_mean = 0, flick_max_frame = 0, flick_max_px = 0;
    };
    Acc acc16, acc8;
    std::vector<float> prev32, prev16, prev8;
    std::vector<float> out32, out16, out8, coc32, coc16, coc8;
    const size_t n = size_t(kW) * kH;
    auto account = [&](Acc& a, const std::vector<float>& coc, const std::vector<float>& out,
                       const std::vector<float>& prev, bool has_prev) {
        double s = 0, m = 0;
        for (size_t i = 0; i < n; ++i) {
            const double e = std::fabs(double(coc[i]) - double(coc32[i]));
            s += e;
            m = std::max(m, e);
        }
        a.coc_mean += s / double(n) / kFrames;
        a.coc_max = std::max(a.coc_max, m);
        if (!has_prev)
            return;
        // Flicker: the change from the previous frame beyond the float32 sequence's change.
        double fs = 0, fm = 0;
        for (size_t i = 0; i < n; ++i)
            for (int c = 0; c < 3; ++c) {
                const double d = std::fabs((double(out[4 * i + c]) - double(prev[4 * i + c])) -
                                           (double(out32[4 * i + c]) - double(prev32[4 * i + c])));
                fs += d;
                fm = std::max(fm, d);
            }
        fs /= 3.0 * double(n);
        a.flick_mean += fs / (kFrames - 1);
        a.flick_max_frame = std::max(a.flick_max_frame, fs);
        a.flick_max_px = std::max(a.flick_max_px, fm);
    };
    double own32_mean = 0; // float32's own frame-to-frame change, for scale
    for (uint32_t k = 0; k < kFrames; ++k) {
        const float u = float(k) / float(kFrames - 1);
        const float d_f = 1.0f / ((1.0f - u) / 2.0f + u / 12.0f);
        st.lens = dof::makeThinLens(st.view, aperture, d_f);
        runGather(f32, st, {}, out32, &coc32, 1);
        runGather(f16, st, {}, out16, &coc16, 1);
        runGather(f8, st, {}, out8, &coc8, 1);
        if (k > 0) {
            double s = 0;
            for (size_t i = 0; i < n; ++i)
                for (int c = 0; c < 3; ++c)
                    s += std::fabs(double(out32[4 * i + c]) - double(prev32[4 * i + c]));
            own32_mean += s / (3.0 * double(n)) / (kFrames - 1);
        }
        account(acc16, coc16, out16, prev16, k > 0);
        account(acc8, coc8, out8, prev8, k > 0);
        prev32 = out32, prev16 = out16, prev8 = out8;
    }
    const dof::CocAffine ca = dof::cocAffine(st.lens, st.view);
    std::printf("focus pull: demo %ux%u, %u frames, d_f 2 -> 12 (uniform in 1/d_f), E = %g, "
                "a = %.1f px per unit D\n",
                kW, kH, kFrames, double(aperture), ca.a);
    std::printf("float32 own mean frame-to-frame change: %.5f\n", own32_mean);
    std::printf("| depth | mean CoC error px | max CoC error px | mean flicker | worst frame "
                "flicker | worst pixel flicker |\n");
    for (auto [name, a] :
         {std::pair<const char*, Acc&>{"unorm16", acc16}, {"unorm8 (emulated)", acc8}})
        std::printf("| %s | %.5f | %.4f | %.6f | %.6f | %.4f |\n", name, a.coc_mean, a.coc_max,
                    a.flick_mean, a.flick_max_frame, a.flick_max_px);
    std::printf("float32 CoC bound: a * 2^-25 = %.2e px\n", ca.a * std::ldexp(1.0, -25));
}

// Filter cost against the maximum radius (the paper: cost grows by 45% at 11 px and 70% at
// 13 px over 9 px). demo at 800x600 with 4x its aperture so every radius is used; inline.
TEST(GatherBench, CostAgainstMaxRadius) {
    if (!benchDir())
        GTEST_SKIP() << "set FOCAL_GATHER_BENCH";
    BenchScene st = setupOf("demo", 800, 600);
    st.lens.aperture_radius *= 4.0f;
    const raster::Frame pin = renderPinhole(st, raster::DepthFormat::Float32);
    std::printf("| R px | taps | ms (coc+V+H) | Msamples | ns/sample | vs R=5 |\n");
    double base = 0;
    for (float r : {5.0f, 6.0f, 7.0f, 9.0f, 13.0f, 17.0f, 25.0f, 33.0f, 65.0f}) {
        dof::GatherSettings s;
        s.max_radius_px = r;
        std::vector<float> out;
        const Timed t = runGather(pin, st, s, out, nullptr, 3);
        if (r == 5.0f)
            base = t.ms;
        std::printf("| %g | %u | %.1f | %.1f | %.2f | %.2fx |\n", double(r),
                    2 * (uint32_t(std::ceil(r)) - 1) + 1, t.ms, double(t.stats.samples) * 1e-6,
                    t.ms * 1e6 / double(std::max<uint64_t>(1, t.stats.samples)), t.ms / base);
    }
}

} // namespace
} // namespace focal::test
