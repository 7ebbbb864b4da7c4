// A method's settings described once (issue 20 part 2). Each settings struct (AccumSettings,
// GatherSettings, MultiviewSettings, MultilayerSettings) has one table with a row per parameter:
// its name (the field's), its command-line spelling, its range or choices, the paper section it
// implements and one line of help. Validation and its messages come from the table here; the
// command line's options, --help, the --stats parameters and the bench sweeps are generated from
// it in apps/settings_options.h. A default is the struct's own member initialiser, read from a
// default-constructed struct, so it is written once.
//
// Consumes settings structs; produces text and Status values the caller owns. The tables are
// static data. No I/O, no allocation beyond the strings returned.
#pragma once

#include <raster/status.h>

#include <cstdint>
#include <limits>
#include <span>
#include <string>
#include <string_view>
#include <type_traits>
#include <vector>

namespace dof {

// An unbounded range's max, and the value of the spelling "inf" (a double: the rows hold doubles).
inline constexpr double kUnbounded = std::numeric_limits<double>::infinity();

enum class ParamType : uint8_t {
    Number, // a float or integer field in [min, max] ((min, max] with min_open)
    Switch, // a bool spelled on|off
    Flag,   // a bool set by naming it (a command-line flag without a value)
    Choice, // an enum (or a bool) spelled by one of `choices`
    List,   // a std::vector<uint32_t>, comma-separated, each entry in [min, max]
};

// One spelling of a Choice (the enum's value), or a Number's value outside its range ("inf",
// "auto").
struct ParamChoice {
    std::string_view spelling = {};
    double value = 0.0;
};

// A Choice's spelling of an enum value (or of a bool).
template <class E> constexpr ParamChoice choice(std::string_view spelling, E value) {
    if constexpr (std::is_enum_v<E>)
        return {spelling, double(std::underlying_type_t<E>(value))};
    else
        return {spelling, double(value)};
}

// What a parameter is, independent of the struct it lives in.
struct ParamInfo {
    std::string_view name = {}; // the field: what library messages and --stats call it
    std::string_view flag = {}; // the command-line option, without "--"
    ParamType type = ParamType::Number;
    double min = 0.0, max = 0.0; // Number and List entries
    bool min_open = false;       // Number: min itself is not allowed
    // Number: one value outside the range and its spelling, e.g. {"inf", +inf} for "no limit"
    // or {"auto", -1}; empty spelling: none.
    ParamChoice special = {};
    std::span<const ParamChoice> choices = {}; // Choice
    std::string_view paper = {};               // "Lee et al. 2009, §4.1 Eq. 4"; empty: focal's own
    std::string_view help = {};                // one line, without the range (paramHelp adds it)
    // Filled from the field's type by Param's constructor.
    bool integer = false;   // whole numbers only
    bool single = false;    // a float field: printed with float's shortest spelling
    bool unsigned_ = false; // an unsigned field (its range starts at 0 or above)
};

// How a table reads and writes its struct's field: numbers, bools and enums through double
// (exact for float, int32 and uint32), lists by reference.
template <class S> struct ParamField {
    double (*get)(const S&) = nullptr;
    void (*set)(S&, double) = nullptr;
    const std::vector<uint32_t>& (*list)(const S&) = nullptr;
    std::vector<uint32_t>& (*list_ref)(S&) = nullptr;
    bool integer = false, single = false, unsigned_ = false;
};

namespace settings_detail {
template <class> struct MemberOf;
template <class S, class T> struct MemberOf<T S::*> {
    using Struct = S;
    using Value = T;
};
} // namespace settings_detail

// The accessors of the field `Member` (a pointer to a data member).
template <auto Member> constexpr auto field() {
    using S = typename settings_detail::MemberOf<decltype(Member)>::Struct;
    using T = typename settings_detail::MemberOf<decltype(Member)>::Value;
    ParamField<S> f;
    if constexpr (std::is_same_v<T, std::vector<uint32_t>>) {
        f.list = [](const S& s) -> const std::vector<uint32_t>& { return s.*Member; };
        f.list_ref = [](S& s) -> std::vector<uint32_t>& { return s.*Member; };
        f.integer = f.unsigned_ = true;
    } else if constexpr (std::is_enum_v<T>) {
        f.get = [](const S& s) { return double(std::underlying_type_t<T>(s.*Member)); };
        f.set = [](S& s, double v) { s.*Member = T(std::underlying_type_t<T>(v)); };
        f.integer = true;
    } else {
        static_assert(std::is_arithmetic_v<T>, "a table field is a number, bool, enum or list");
        f.get = [](const S& s) { return double(s.*Member); };
        if constexpr (std::is_same_v<T, bool>)
            f.set = [](S& s, double v) { s.*Member = v != 0.0; };
        else
            f.set = [](S& s, double v) { s.*Member = T(v); };
        f.integer = std::is_integral_v<T>;
        f.single = std::is_same_v<T, float>;
        f.unsigned_ = std::is_unsigned_v<T>;
    }
    return f;
}

// One row of a settings table.
template <class S> struct Param {
    using Struct = S;
    constexpr Param(ParamInfo i, ParamField<S> f) : info(i), field(f) {
        info.integer = f.integer;
        info.single = f.single;
        info.unsigned_ = f.unsigned_;
    }
    ParamInfo info;
    ParamField<S> field;
};

// The help line: "HELP (RANGE or CHOICES; PAPER)".
// A choice row's spellings: "scan|false-position".
std::string paramChoices(const ParamInfo& p);
// `spellings`: false leaves out a switch's or choice's spellings (a --help line shows them as
// the value's type).
std::string paramHelp(const ParamInfo& p, bool spellings = true);
// A value as the command line spells it: "2", "0.1", "on", "scan", "inf".
std::string formatParamValue(const ParamInfo& p, double value);
std::string formatParamList(const std::vector<uint32_t>& values);
// Rejects a value outside the parameter's range or choices. Messages read
// "METHOD settings: NAME must be in (0, 64], got -1".
raster::Status checkParamValue(std::string_view method, const ParamInfo& p, double value);
raster::Status checkParamList(std::string_view method, const ParamInfo& p,
                              const std::vector<uint32_t>& values);
// Parses the command line's spelling and checks it (Flag: "on"/"off" as for a Switch).
raster::Result<double> parseParamValue(std::string_view method, const ParamInfo& p,
                                       std::string_view text);
raster::Result<std::vector<uint32_t>> parseParamList(std::string_view method, const ParamInfo& p,
                                                     std::string_view text);

template <class S> std::string formatParam(const Param<S>& p, const S& s) {
    return p.info.type == ParamType::List ? formatParamList(p.field.list(s))
                                          : formatParamValue(p.info, p.field.get(s));
}

// Sets the field from its spelling; on failure `s` is unchanged.
template <class S>
raster::Status parseParam(std::string_view method, const Param<S>& p, S& s, std::string_view text) {
    if (p.info.type == ParamType::List) {
        raster::Result<std::vector<uint32_t>> v = parseParamList(method, p.info, text);
        if (!v.ok())
            return v.status();
        p.field.list_ref(s) = std::move(*v);
        return {};
    }
    raster::Result<double> v = parseParamValue(method, p.info, text);
    if (!v.ok())
        return v.status();
    p.field.set(s, *v);
    return {};
}

// Every row's value in range (the checks between fields stay with each method's validate()).
template <class S>
raster::Status checkParams(std::string_view method, std::span<const Param<S>> table, const S& s) {
    for (const Param<S>& p : table) {
        raster::Status st = p.info.type == ParamType::List
                                ? checkParamList(method, p.info, p.field.list(s))
                                : checkParamValue(method, p.info, p.field.get(s));
        if (!st.ok())
            return st;
    }
    return {};
}

// The error every settings check returns: "METHOD settings: WHAT".
raster::Status settingsError(std::string_view method, std::string_view what);

} // namespace dof
