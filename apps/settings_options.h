// The command line's side of the settings tables (dof/settings_table.h): one `focal render`
// option per table row with its help and default, the --stats parameters of a settings struct,
// and library messages with settings names turned into option names. Consumes the tables;
// produces CLI11 options bound to the caller's settings struct (which must outlive parsing) and
// JSON the caller owns.
#pragma once

#include <dof/settings_table.h>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include <cmath>
#include <span>
#include <string>
#include <string_view>

namespace focal {

// The CLI11 validator message of a value the table rejects: the library's message without its
// "METHOD settings: NAME " prefix ("must be in [0, 1], got 2").
std::string optionProblem(const raster::Status& status, std::string_view method,
                          const dof::ParamInfo& p);

// The --help line of a row: "METHOD: HELP (RANGE; PAPER)", other settings named by their options.
std::string optionHelp(std::string_view method, const dof::ParamInfo& p);

// The value's shape in --help: "NUMBER", "NUMBER|inf", "on|off", "scan|false-position", "N,N,...".
std::string optionTypeName(const dof::ParamInfo& p);

// Adds "--FLAG" for every row of `table` to `cmd`, parsed into `values`. The help is the row's
// ("METHOD: HELP (RANGE; PAPER)") and the default shown is a default-constructed S's.
template <class S>
void addSettingsOptions(CLI::App& cmd, std::string_view method,
                        std::span<const dof::Param<S>> table, S& values) {
    const S defaults{};
    for (const dof::Param<S>& p : table) {
        const std::string name = "--" + std::string(p.info.flag);
        const std::string help = optionHelp(method, p.info);
        if (p.info.type == dof::ParamType::Flag) {
            cmd.add_flag_callback(
                name, [&values, &p] { p.field.set(values, 1.0); }, help);
            continue;
        }
        cmd.add_option_function<std::string>(
               name,
               [&values, &p, method](const std::string& text) {
                   // Checked by the validator below.
                   (void)dof::parseParam(method, p, values, text);
               },
               help)
            ->default_str(dof::formatParam(p, defaults))
            ->check(CLI::Validator(
                [&p, method](std::string& text) {
                    const raster::Status s =
                        p.info.type == dof::ParamType::List
                            ? dof::parseParamList(method, p.info, text).status()
                            : dof::parseParamValue(method, p.info, text).status();
                    return s.ok() ? std::string() : optionProblem(s, method, p.info);
                },
                ""))
            ->type_name(optionTypeName(p.info));
    }
}

// Every row's value for --stats: numbers as numbers (a special value, e.g. inf, as its
// spelling), on|off as booleans, choices and lists as the command line spells them.
template <class S> nlohmann::json settingsJson(std::span<const dof::Param<S>> table, const S& s) {
    nlohmann::json j = nlohmann::json::object();
    for (const dof::Param<S>& p : table) {
        const std::string name(p.info.name);
        switch (p.info.type) {
        case dof::ParamType::Switch:
        case dof::ParamType::Flag:
            j[name] = p.field.get(s) != 0.0;
            break;
        case dof::ParamType::List:
            j[name] = p.field.list(s);
            break;
        case dof::ParamType::Choice:
            j[name] = dof::formatParam(p, s);
            break;
        case dof::ParamType::Number: {
            const double v = p.field.get(s);
            if (!p.info.special.spelling.empty() && v == p.info.special.value)
                j[name] = std::string(p.info.special.spelling);
            else if (p.info.integer)
                j[name] = int64_t(v);
            else if (p.info.single)
                j[name] = float(v);
            else
                j[name] = v;
            break;
        }
        }
    }
    return j;
}

// `message` with the library's settings names replaced by the options that set them: the lens
// request's fields (aperture_radius, fstop, focal_length_mm, sensor_height_mm, focus_distance,
// focus_pixel), the view's znear, the memory_budget, and in a message "METHOD settings: ..."
// that method's table names ("multiview settings: layers must ..." becomes "multiview: --layers
// must ..."). Whole identifiers only, and not inside a path.
std::string withOptionNames(const std::string& message);

// The option that sets `method`'s setting `name` ("--layer-spacing" for multiview's
// layer_spacing_px; "--samples" for samples); empty when the method has no such setting.
std::string optionFor(std::string_view method, std::string_view name);

} // namespace focal
