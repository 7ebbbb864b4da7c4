#include "apps/bench_plots.h"

#include "apps/report_text.h"
#include "apps/text_file.h"

#include <algorithm>
#include <cstdlib>
#include <filesystem>

namespace focal {

bool haveGnuplot() {
    return std::system("command -v gnuplot >/dev/null 2>&1") == 0;
}

namespace {

// One data block per method with points, then the Pareto front's block; `titles` receives the
// methods that have a block, in order.
std::string plotData(const Json& rows, const std::vector<size_t>& idx,
                     const std::vector<std::string>& methods, std::vector<std::string>& titles) {
    std::string dat;
    for (const std::string& m : methods) {
        std::string block;
        for (size_t i : idx)
            if (rows[i]["method"] == m && rows[i]["psnr_srgb_db"].is_number())
                block += fmt("%.6g", rows[i]["ms_median"].get<double>()) + " " +
                         fmt("%.6g", rows[i]["psnr_srgb_db"].get<double>()) + " " +
                         fmt("%.6g", rows[i]["ms_min"].get<double>()) + " " +
                         fmt("%.6g", rows[i]["ms_max"].get<double>()) + " \"" +
                         rows[i]["setting"].get<std::string>() + "\"\n";
        if (block.empty())
            continue;
        dat += "# " + m + "\n" + block + "\n\n";
        titles.push_back(m);
    }
    std::vector<size_t> front;
    for (size_t i : idx)
        if (rows[i].value("pareto", false) && rows[i]["psnr_srgb_db"].is_number())
            front.push_back(i);
    std::sort(front.begin(), front.end(), [&](size_t a, size_t b) {
        return rows[a]["ms_median"].get<double>() < rows[b]["ms_median"].get<double>();
    });
    dat += "# pareto\n";
    for (size_t i : front)
        dat += fmt("%.6g", rows[i]["ms_median"].get<double>()) + " " +
               fmt("%.6g", rows[i]["psnr_srgb_db"].get<double>()) + "\n";
    return dat + "\n\n";
}

std::string plotScript(const std::string& base, const std::string& title,
                       const std::vector<std::string>& titles) {
    static const char* kColors[] = {"#000000", "#0072b2", "#e69f00",
                                    "#009e73", "#cc79a7", "#d55e00"};
    std::string gp = "set terminal pngcairo size 900,600 noenhanced font ',10'\n"
                     "set output '" +
                     base +
                     ".png'\n"
                     "set title '" +
                     title +
                     "'\n"
                     "set logscale x\nset xlabel 'median wall time per frame (ms, log scale)'\n"
                     "set ylabel 'PSNR against the accum reference (sRGB, dB)'\n"
                     "set key bottom right\nset grid\n"
                     "plot ";
    const size_t blocks = titles.size();
    for (size_t b = 0; b < blocks; ++b)
        gp += "'" + base + ".dat' index " + std::to_string(b) +
              " using 1:2:3:4 with xerrorbars pt " + std::to_string(5 + 2 * b) +
              " ps 1.5 lc rgb '" + kColors[b % 6] + "' title '" + titles[b] + "', '" + base +
              ".dat' index " + std::to_string(b) +
              " using 1:2:5 with labels offset 0,1 font ',8' notitle, ";
    gp += "'" + base + ".dat' index " + std::to_string(blocks) +
          " using 1:2 with lines lw 2 dt 2 lc rgb 'gray50' title 'Pareto front'\n";
    return gp;
}

} // namespace

raster::Status plotScene(const std::string& dir, const std::string& scene, const Json& rows,
                         const std::vector<size_t>& idx, const std::vector<std::string>& methods,
                         const std::string& title) {
    const std::string base = (std::filesystem::path(dir) / "plots" / ("bench_" + scene)).string();
    std::vector<std::string> titles;
    if (raster::Status s = writeTextFile(base + ".dat", plotData(rows, idx, methods, titles));
        !s.ok())
        return s;
    if (raster::Status s = writeTextFile(base + ".gp", plotScript(base, title, titles)); !s.ok())
        return s;
    const std::string cmd = "gnuplot '" + base + ".gp' 2>'" + base + ".log'";
    if (std::system(cmd.c_str()) != 0)
        return raster::Status::error("gnuplot failed on " + base + ".gp (see " + base + ".log)");
    return {};
}

} // namespace focal
