#include "apps/settings_options.h"

#include <dof/accum.h>
#include <dof/gather.h>
#include <dof/multilayer.h>
#include <dof/multiview.h>

#include <algorithm>
#include <cctype>
#include <utility>
#include <vector>

namespace focal {

namespace {

using Spelling = std::pair<std::string_view, std::string>; // settings name, option

template <class S>
void addSpellings(std::span<const dof::Param<S>> table, std::vector<Spelling>& out) {
    for (const dof::Param<S>& p : table)
        out.emplace_back(p.info.name, "--" + std::string(p.info.flag));
}

// The names a message from `method`'s settings checks may use.
std::vector<Spelling> methodSpellings(std::string_view method) {
    std::vector<Spelling> out;
    if (method == "accum")
        addSpellings(dof::accumParams(), out);
    else if (method == "gather")
        addSpellings(dof::gatherParams(), out);
    else if (method == "multiview")
        addSpellings(dof::multiviewParams(), out);
    else if (method == "multilayer")
        addSpellings(dof::multilayerParams(), out);
    out.emplace_back("samples", "--samples"); // the lens samples every method but pinhole reads
    return out;
}

bool isIdentifier(char c) {
    return std::isalnum(static_cast<unsigned char>(c)) || c == '_';
}
bool isPathCharacter(char c) {
    return c == '/' || c == '.' || c == '\\';
}

// `text` with every whole identifier named in `spellings` replaced, except inside a path.
std::string replaceWords(const std::string& text, const std::vector<Spelling>& spellings) {
    std::string out;
    for (size_t i = 0; i < text.size();) {
        size_t end = i;
        while (end < text.size() && isIdentifier(text[end]))
            ++end;
        if (end == i) {
            out += text[i++];
            continue;
        }
        const std::string_view word = std::string_view(text).substr(i, end - i);
        const bool in_path = (i > 0 && isPathCharacter(text[i - 1])) ||
                             (end < text.size() && isPathCharacter(text[end]) &&
                              end + 1 < text.size() && isIdentifier(text[end + 1]));
        const auto hit = std::find_if(spellings.begin(), spellings.end(),
                                      [&](const Spelling& s) { return s.first == word; });
        out += hit != spellings.end() && !in_path ? std::string_view(hit->second) : word;
        i = end;
    }
    return out;
}

} // namespace

std::string optionTypeName(const dof::ParamInfo& p) {
    switch (p.type) {
    case dof::ParamType::Number:
        return p.special.spelling.empty() ? "NUMBER" : "NUMBER|" + std::string(p.special.spelling);
    case dof::ParamType::List:
        return "N,N,...";
    case dof::ParamType::Choice:
        return dof::paramChoices(p);
    case dof::ParamType::Switch:
    case dof::ParamType::Flag:
        break;
    }
    return "on|off";
}

std::string optionProblem(const raster::Status& status, std::string_view method,
                          const dof::ParamInfo& p) {
    const std::string prefix = std::string(method) + " settings: " + std::string(p.name) + " ";
    const std::string& m = status.message();
    return m.rfind(prefix, 0) == 0 ? m.substr(prefix.size()) : withOptionNames(m);
}

std::string withOptionNames(const std::string& message) {
    std::vector<Spelling> spellings = {{"aperture_radius", "--aperture-radius"},
                                       {"fstop", "--fstop"},
                                       {"focal_length_mm", "--focal-length"},
                                       {"sensor_height_mm", "--sensor-height"},
                                       {"focus_distance", "--focus-distance"},
                                       {"focus_pixel", "--focus-pixel"},
                                       {"znear", "--near"},
                                       {"blades", "--aperture-blades"},
                                       {"rotation_deg", "--aperture-rotation"},
                                       {"memory_budget", "--memory-budget"}};
    std::string text = message;
    const size_t colon = text.find(" settings: ");
    if (colon != std::string::npos && colon == text.find_first_of(" :")) {
        std::vector<Spelling> own = methodSpellings(std::string_view(text).substr(0, colon));
        if (own.size() > 1) {
            spellings.insert(spellings.end(), own.begin(), own.end());
            text.erase(colon, std::string_view(" settings").size()); // "multiview: ..."
        }
    }
    return replaceWords(text, spellings);
}

std::string optionHelp(std::string_view method, const dof::ParamInfo& p) {
    // Only the snake_case names: a help line's plain words ("layers", "cone") are English.
    std::vector<Spelling> spellings = methodSpellings(method);
    std::erase_if(spellings, [](const Spelling& s) { return s.first.find('_') == s.first.npos; });
    return std::string(method) + ": " + replaceWords(dof::paramHelp(p, false), spellings);
}

std::string optionFor(std::string_view method, std::string_view name) {
    for (const Spelling& s : methodSpellings(method))
        if (s.first == name)
            return s.second;
    return {};
}

} // namespace focal
