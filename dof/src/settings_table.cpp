#include <dof/settings_table.h>

#include <charconv>
#include <cmath>
#include <cstdio>

namespace dof {

using raster::Result;
using raster::Status;

namespace {

std::string number(const ParamInfo& p, double v) {
    if (p.special.spelling.size() && v == p.special.value)
        return std::string(p.special.spelling);
    char buf[32];
    std::to_chars_result r = p.single ? std::to_chars(buf, buf + sizeof buf, float(v))
                                      : std::to_chars(buf, buf + sizeof buf, v);
    return std::string(buf, r.ptr);
}

// "[0, 64]", "(0, 1]", ">= 0", "> 0".
std::string rangeText(const ParamInfo& p) {
    const std::string lo = number(p, p.min);
    if (std::isinf(p.max))
        return std::string(p.min_open ? "> " : ">= ") + lo;
    return std::string(p.min_open ? "(" : "[") + lo + ", " + number(p, p.max) + "]";
}

// "in [0, 64]", "> 0": what a value must be.
std::string rangePhrase(const ParamInfo& p) {
    return (std::isinf(p.max) ? "" : "in ") + rangeText(p);
}

std::string quoted(std::string_view text) {
    return "'" + std::string(text) + "'";
}

} // namespace

std::string paramChoices(const ParamInfo& p) {
    std::string out;
    for (const ParamChoice& c : p.choices)
        out += (out.empty() ? "" : "|") + std::string(c.spelling);
    return out;
}

Status settingsError(std::string_view method, std::string_view what) {
    return Status::error(std::string(method) + " settings: " + std::string(what));
}

std::string paramHelp(const ParamInfo& p, bool spellings) {
    std::string out(p.help);
    std::string detail;
    switch (p.type) {
    case ParamType::Number:
        detail = rangeText(p);
        if (p.special.spelling.size())
            detail += " or " + std::string(p.special.spelling);
        break;
    case ParamType::List:
        detail = "comma-separated, each " + rangePhrase(p);
        break;
    case ParamType::Choice:
        detail = spellings ? paramChoices(p) : "";
        break;
    case ParamType::Switch:
        detail = spellings ? "on|off" : "";
        break;
    case ParamType::Flag:
        break;
    }
    if (p.paper.size())
        detail += std::string(detail.empty() ? "" : "; ") + std::string(p.paper);
    if (!detail.empty())
        out += " (" + detail + ")";
    return out;
}

std::string formatParamValue(const ParamInfo& p, double value) {
    switch (p.type) {
    case ParamType::Switch:
    case ParamType::Flag:
        return value != 0.0 ? "on" : "off";
    case ParamType::Choice:
        for (const ParamChoice& c : p.choices)
            if (c.value == value)
                return std::string(c.spelling);
        return "?";
    case ParamType::Number:
    case ParamType::List:
        break;
    }
    return number(p, value);
}

std::string formatParamList(const std::vector<uint32_t>& values) {
    std::string out;
    for (uint32_t v : values)
        out += (out.empty() ? "" : ",") + std::to_string(v);
    return out;
}

// Allocates only for a message: a frame validates its settings every time it renders.
Status checkParamValue(std::string_view method, const ParamInfo& p, double v) {
    switch (p.type) {
    case ParamType::Switch:
    case ParamType::Flag:
        return {};
    case ParamType::Choice:
        for (const ParamChoice& c : p.choices)
            if (c.value == v)
                return {};
        return settingsError(method, std::string(p.name) + " must be one of " + paramChoices(p));
    case ParamType::Number:
    case ParamType::List:
        break;
    }
    if (p.special.spelling.size() && v == p.special.value)
        return {};
    const bool in_range = std::isfinite(v) && (p.min_open ? v > p.min : v >= p.min) && v <= p.max;
    if (!in_range || (p.integer && v != std::floor(v))) {
        std::string what = std::string(p.name) + " must be " +
                           (p.integer ? "a whole number " : "") + rangePhrase(p);
        if (p.special.spelling.size())
            what += " or " + std::string(p.special.spelling);
        ParamInfo plain = p;
        plain.special = {};
        return settingsError(method, what + ", got " + number(plain, v));
    }
    return {};
}

Status checkParamList(std::string_view method, const ParamInfo& p,
                      const std::vector<uint32_t>& values) {
    for (uint32_t v : values)
        if (double(v) < p.min || double(v) > p.max)
            return settingsError(method, std::string(p.name) + " entries must be " +
                                             rangePhrase(p) + ", got " + std::to_string(v));
    return {};
}

Result<double> parseParamValue(std::string_view method, const ParamInfo& p, std::string_view text) {
    const std::string name(p.name);
    switch (p.type) {
    case ParamType::Switch:
    case ParamType::Flag:
        if (text == "on" || text == "true")
            return 1.0;
        if (text == "off" || text == "false")
            return 0.0;
        return settingsError(method, name + " must be on or off, got " + quoted(text));
    case ParamType::Choice:
        for (const ParamChoice& c : p.choices)
            if (c.spelling == text)
                return c.value;
        return settingsError(method,
                             name + " must be one of " + paramChoices(p) + ", got " + quoted(text));
    case ParamType::Number:
    case ParamType::List:
        break;
    }
    if (p.special.spelling.size() && text == p.special.spelling)
        return p.special.value;
    double v = 0.0;
    const char* first = text.data();
    const char* last = first + text.size();
    const std::from_chars_result r = std::from_chars(first, last, v);
    if (text.empty() || r.ec != std::errc() || r.ptr != last || !std::isfinite(v)) {
        std::string what = name + " must be a number";
        if (p.special.spelling.size())
            what += " or " + std::string(p.special.spelling);
        return settingsError(method, what + ", got " + quoted(text));
    }
    if (Status s = checkParamValue(method, p, v); !s.ok())
        return s;
    return v;
}

Result<std::vector<uint32_t>> parseParamList(std::string_view method, const ParamInfo& p,
                                             std::string_view text) {
    std::vector<uint32_t> out;
    size_t at = 0;
    while (at <= text.size()) {
        const size_t end = std::min(text.find(',', at), text.size());
        const std::string_view item = text.substr(at, end - at);
        uint32_t v = 0;
        const std::from_chars_result r = std::from_chars(item.data(), item.data() + item.size(), v);
        if (item.empty() || r.ec != std::errc() || r.ptr != item.data() + item.size())
            return settingsError(method, std::string(p.name) +
                                             " must be comma-separated whole numbers, got " +
                                             quoted(text));
        out.push_back(v);
        at = end + 1;
    }
    if (Status s = checkParamList(method, p, out); !s.ok())
        return s;
    return out;
}

} // namespace dof
