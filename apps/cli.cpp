#include "apps/cli.h"

#include "apps/bench_command.h"
#include "apps/compare_command.h"
#include "apps/render_command.h"
#include "apps/scene_info.h"
#include "apps/scene_source.h"

#include <CLI/CLI.hpp>

#include <cstdio>

namespace focal {

namespace {

int runInfo(const std::string& spec) {
    raster::Result<raster::Scene> scene = loadScene(spec);
    if (!scene.ok()) {
        std::fprintf(stderr, "focal: error: %s\n", scene.status().message().c_str());
        return 1;
    }
    std::fputs(describeScene(*scene).c_str(), stdout);
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

    BenchArgs bench_args;
    CLI::App* bench = addBenchCommand(app, bench_args);

    std::string info_scene;
    CLI::App* info = app.add_subcommand("info", "Describe a scene: triangles, meshes, materials, "
                                                "textures, cameras, bounds, extensions");
    info->add_option("scene", info_scene, "glTF file (.gltf/.glb) or builtin:NAME")->required();

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
    if (render->parsed())
        return runRender(render_args);
    if (compare->parsed())
        return runCompare(compare_args);
    if (bench->parsed())
        return runBench(bench_args);
    if (info->parsed())
        return runInfo(info_scene);
    return 2;
}

} // namespace focal
