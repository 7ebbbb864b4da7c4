#include "apps/cli.h"

#include "apps/bench_command.h"
#include "apps/compare_command.h"
#include "apps/hash_command.h"
#include "apps/render_command.h"
#include "apps/scene_info.h"
#include "apps/scene_source.h"
#include "apps/steps_command.h"

#include <raster/renderer.h>
#include <raster/task_pool.h>

#include <CLI/CLI.hpp>

#include <algorithm>
#include <cstdio>
#include <new>
#include <thread>

namespace focal {

namespace {

struct InfoArgs {
    std::string scene;
    uint32_t threads = 1;
    bool all_images = false;
};

int runInfo(const InfoArgs& args) {
    // Decode what some shading mode samples (so a broken colour texture is reported as a
    // render would report it), or every image with --all-images.
    raster::ImportOptions options;
    if (!args.all_images) {
        raster::TextureRoles roles;
        for (const raster::ShadingMode mode :
             {raster::ShadingMode::Material, raster::ShadingMode::Unlit, raster::ShadingMode::Lit})
            roles.bits |= raster::sampledTextureRoles(mode).bits;
        options.roles = roles;
    }
    raster::TaskPool pool(args.threads);
    options.pool = &pool;
    options.memory_budget = raster::defaultMemoryBudget();
    raster::ImportStats stats;
    raster::Result<raster::Scene> scene = loadScene(args.scene, options, &stats);
    if (!scene.ok()) {
        std::fprintf(stderr, "focal: error: %s\n", scene.status().message().c_str());
        return 1;
    }
    std::fputs(describeScene(*scene).c_str(), stdout);
    std::fputs(describeLoad(stats).c_str(), stdout);
    return 0;
}

} // namespace

int runCli(int argc, char** argv) {
    CLI::App app{"focal: a deterministic CPU rasterizer for depth-of-field research"};
    app.require_subcommand(1);
    app.set_version_flag("--version", "focal 0.1.0");

    RenderArgs render_args;
    CLI::App* render = addRenderCommand(app, render_args);

    CompareArgs compare_args;
    CLI::App* compare = addCompareCommand(app, compare_args);

    HashArgs hash_args;
    CLI::App* hash = addHashCommand(app, hash_args);

    BenchArgs bench_args;
    CLI::App* bench = addBenchCommand(app, bench_args);

    StepsArgs steps_args;
    CLI::App* steps = addStepsCommand(app, steps_args);
    steps_args.command.assign(argv, argv + argc);
    if (!steps_args.command.empty())
        steps_args.command.front() = "focal";

    ProbeArgs probe_args;
    CLI::App* probe = addProbeCommand(app, probe_args);

    InfoArgs info_args;
    info_args.threads = std::max(1u, std::thread::hardware_concurrency());
    CLI::App* info = app.add_subcommand("info", "Describe a scene: triangles, meshes, materials, "
                                                "textures, cameras, bounds, extensions, load time");
    info->add_option("scene", info_args.scene, "glTF file (.gltf/.glb) or builtin:NAME")
        ->required();
    info->add_option("--threads", info_args.threads,
                     "worker threads decoding images (0 = run inline on the caller)")
        ->capture_default_str()
        ->check(CLI::Range(0, 256));
    info->add_flag("--all-images", info_args.all_images,
                   "decode every image, also those no shading mode samples (normal, occlusion, "
                   "metallic-roughness maps), e.g. to check that they decode");

    try {
        app.parse(argc, argv);
    } catch (const CLI::CallForHelp& e) {
        return app.exit(e);
    } catch (const CLI::CallForAllHelp& e) {
        return app.exit(e);
    } catch (const CLI::CallForVersion& e) {
        return app.exit(e);
    } catch (const CLI::ParseError& e) {
        std::fprintf(stderr, "focal: error: %s (see focal --help)\n", e.what());
        return 2;
    }
    // The budget checks catch what can be foreseen; an allocation that still fails (the machine
    // is short of memory, or a buffer nobody budgeted) is one error line, never std::terminate.
    try {
        if (render->parsed())
            return runRender(render_args);
        if (compare->parsed())
            return runCompare(compare_args);
        if (hash->parsed())
            return runHash(hash_args);
        if (bench->parsed())
            return runBench(bench_args);
        if (steps->parsed())
            return runSteps(steps_args);
        if (probe->parsed())
            return runProbe(probe_args);
        if (info->parsed())
            return runInfo(info_args);
    } catch (const std::bad_alloc&) {
        std::fprintf(stderr, "focal: error: out of memory (lower --width/--height, --samples or "
                             "--layers, or set --memory-budget to fail before allocating)\n");
        return 1;
    }
    return 2;
}

} // namespace focal
