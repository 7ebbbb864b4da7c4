// dof/settings_table.h: every method's settings table (accum, gather, multiview, multilayer) is
// well formed, its defaults are valid and spell back to themselves, and its ranges reject what
// they say they reject, with messages that name the setting. apps/settings_options.h: the
// command line has one option per row, shows its default, and maps setting names to options.
#include "apps/settings_options.h"
#include "support/subprocess.h"

#include <dof/accum.h>
#include <dof/gather.h>
#include <dof/multilayer.h>
#include <dof/multiview.h>

#include <gtest/gtest.h>

#include <cmath>
#include <set>
#include <string>

namespace focal::test {
namespace {

// Runs `check` on every table with the method's name.
template <class F> void forEachTable(F&& check) {
    check("accum", dof::accumParams());
    check("gather", dof::gatherParams());
    check("multiview", dof::multiviewParams());
    check("multilayer", dof::multilayerParams());
}

TEST(SettingsTable, NamesAndFlagsAreUniqueAndEveryRowIsDescribed) {
    forEachTable([](std::string_view method, auto table) {
        ASSERT_FALSE(table.empty()) << method;
        std::set<std::string_view> names, flags;
        for (const auto& p : table) {
            EXPECT_TRUE(names.insert(p.info.name).second) << method << " " << p.info.name;
            EXPECT_TRUE(flags.insert(p.info.flag).second) << method << " " << p.info.flag;
            EXPECT_FALSE(p.info.help.empty()) << method << " " << p.info.name;
            if (p.info.type == dof::ParamType::Choice) {
                EXPECT_GE(p.info.choices.size(), 2u) << method << " " << p.info.name;
            }
            if (p.info.type == dof::ParamType::Number || p.info.type == dof::ParamType::List) {
                EXPECT_LE(p.info.min, p.info.max) << method << " " << p.info.name;
            }
        }
    });
}

TEST(SettingsTable, DefaultsAreValidAndSpellBackToThemselves) {
    forEachTable([](std::string_view method, auto table) {
        using S = typename decltype(table)::element_type::Struct;
        const S defaults{};
        for (const auto& p : table) {
            const std::string text = dof::formatParam(p, defaults);
            S parsed{};
            // Start from another value where there is one, so the parse must write the field.
            if (p.info.type != dof::ParamType::List)
                p.field.set(parsed, p.info.type == dof::ParamType::Choice
                                        ? p.info.choices.back().value
                                        : p.field.get(defaults) + 1.0);
            const raster::Status st = dof::parseParam(method, p, parsed, text);
            ASSERT_TRUE(st.ok()) << method << " " << p.info.name << " '" << text
                                 << "': " << st.message();
            if (p.info.type == dof::ParamType::List) {
                EXPECT_EQ(p.field.list(parsed), p.field.list(defaults)) << p.info.name;
            } else {
                EXPECT_EQ(p.field.get(parsed), p.field.get(defaults))
                    << method << " " << p.info.name << " '" << text << "'";
            }
        }
    });
    EXPECT_TRUE(dof::validate(dof::GatherSettings{}).ok());
    EXPECT_TRUE(dof::validate(dof::MultilayerSettings{}).ok());
    EXPECT_TRUE(dof::validate(dof::MultiviewSettings{}, 8).ok());
}

TEST(SettingsTable, RangesRejectWhatTheySayAndNameTheSetting) {
    forEachTable([](std::string_view method, auto table) {
        using S = typename decltype(table)::element_type::Struct;
        const std::string prefix = std::string(method) + " settings: ";
        for (const auto& p : table) {
            if (p.info.type != dof::ParamType::Number)
                continue;
            std::vector<double> bad = {NAN};
            if (std::isfinite(p.info.max))
                bad.push_back(p.info.max + 1.0);
            if (p.info.min_open)
                bad.push_back(p.info.min);
            else if (!p.info.unsigned_ || p.info.min > 0.0)
                bad.push_back(p.info.min - 1.0);
            if (p.info.integer && p.info.max > p.info.min + 1.0)
                bad.push_back(p.info.min + 0.5 + (p.info.min_open ? 1.0 : 0.0));
            for (double v : bad) {
                if (!p.info.special.spelling.empty() && v == p.info.special.value)
                    continue; // "auto" is stored as -1
                const raster::Status st = dof::checkParamValue(method, p.info, v);
                ASSERT_FALSE(st.ok()) << method << " " << p.info.name << " = " << v;
                EXPECT_EQ(st.message().rfind(prefix + std::string(p.info.name) + " must", 0), 0u)
                    << st.message();
            }
            // The whole table check reports the same row.
            if (!p.info.unsigned_ && std::isfinite(p.info.max)) {
                S s{};
                p.field.set(s, p.info.max + 1.0);
                const raster::Status st = dof::checkParams(method, table, s);
                EXPECT_NE(st.message().find(std::string(p.info.name)), std::string::npos)
                    << st.message();
            }
        }
    });
}

TEST(SettingsTable, SpellingsParseAndBadSpellingsAreRejected) {
    const auto table = dof::multiviewParams();
    auto row = [&](std::string_view name) -> const dof::Param<dof::MultiviewSettings>& {
        for (const auto& p : table)
            if (p.info.name == name)
                return p;
        ADD_FAILURE() << name;
        return table.front();
    };
    dof::MultiviewSettings s;
    ASSERT_TRUE(dof::parseParam("multiview", row("thickness_px"), s, "inf").ok());
    EXPECT_TRUE(std::isinf(s.thickness_px));
    EXPECT_EQ(dof::formatParam(row("thickness_px"), s), "inf");
    ASSERT_TRUE(dof::parseParam("multiview", row("culling"), s, "off").ok());
    EXPECT_FALSE(s.culling);
    ASSERT_TRUE(dof::parseParam("multiview", row("traversal"), s, "false-position").ok());
    EXPECT_EQ(dof::formatParam(row("traversal"), s), "false-position");
    const dof::MultiviewSettings before = s;
    for (const char* text : {"", "1e", "nan", "inf ", "0x10", "-inf"})
        EXPECT_FALSE(dof::parseParam("multiview", row("overlap"), s, text).ok()) << text;
    EXPECT_NE(dof::paramHelp(row("culling").info).find("(on|off; Lee et al. 2009, §4.3)"),
              std::string::npos);
    EXPECT_EQ(dof::paramHelp(row("culling").info, false).find("on|off"), std::string::npos);
    EXPECT_FALSE(dof::parseParam("multiview", row("culling"), s, "yes").ok());
    EXPECT_FALSE(dof::parseParam("multiview", row("traversal"), s, "bisect").ok());
    EXPECT_EQ(s.overlap, before.overlap); // a failed parse leaves the field alone
    EXPECT_EQ(s.culling, before.culling);

    const auto ml = dof::multilayerParams();
    dof::MultilayerSettings m;
    for (const auto& p : ml)
        if (p.info.name == "aperture_grids") {
            ASSERT_TRUE(dof::parseParam("multilayer", p, m, "3,4").ok());
            EXPECT_EQ(m.aperture_grids, (std::vector<uint32_t>{3, 4}));
            EXPECT_EQ(dof::formatParam(p, m), "3,4");
            for (const char* text : {"", "3,", ",3", "3;4", "3,x", "3,9"})
                EXPECT_FALSE(dof::parseParam("multilayer", p, m, text).ok()) << text;
            EXPECT_EQ(m.aperture_grids, (std::vector<uint32_t>{3, 4}));
        }
}

TEST(SettingsOptions, MessagesNameTheOptions) {
    EXPECT_EQ(withOptionNames("multiview settings: layer_spacing_px must be > 0, got -1"),
              "multiview: --layer-spacing must be > 0, got -1");
    EXPECT_EQ(withOptionNames("gather settings: max_radius_px must be in [1, 256], got 0.5"),
              "gather: --gather-max-radius must be in [1, 256], got 0.5");
    EXPECT_EQ(withOptionNames("multiview settings: samples must be at least 1"),
              "multiview: --samples must be at least 1");
    // Another method's names and plain words are left alone.
    EXPECT_EQ(withOptionNames("gather settings: layers and epsilon"), "gather: layers and epsilon");
    EXPECT_EQ(optionFor("multiview", "layer_spacing_px"), "--layer-spacing");
    EXPECT_EQ(optionFor("multilayer", "fragments_per_pixel"), "--fragments-per-pixel");
    EXPECT_EQ(optionFor("gather", "layers"), "");
}

TEST(SettingsOptions, EveryRowIsAnOptionWithItsDefaultInHelp) {
    const ProcessResult r = runProcess({FOCAL_BINARY, "render", "--help"});
    ASSERT_EQ(r.exit_code, 0) << r.err;
    forEachTable([&](std::string_view method, auto table) {
        using S = typename decltype(table)::element_type::Struct;
        const S defaults{};
        for (const auto& p : table) {
            std::string expected = "--" + std::string(p.info.flag);
            if (p.info.type != dof::ParamType::Flag)
                expected += " " + optionTypeName(p.info) + "=" + dof::formatParam(p, defaults);
            EXPECT_NE(r.out.find(expected), std::string::npos) << method << ": " << expected;
        }
    });
}

} // namespace
} // namespace focal::test
