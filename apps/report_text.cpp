#include "apps/report_text.h"

#include <algorithm>
#include <cctype>
#include <cstdio>
#include <sstream>

namespace focal {

std::string safeName(const std::string& text) {
    std::string s;
    for (char c : text)
        s += std::isalnum(static_cast<unsigned char>(c)) || c == '-' || c == '.' ? c : '_';
    return s;
}

std::string fmt(const char* format, double v) {
    char buf[64];
    std::snprintf(buf, sizeof buf, format, v);
    return buf;
}

std::string exactText(float v) {
    std::ostringstream s;
    s.precision(9);
    s << v;
    return s.str();
}

std::string htmlEscape(const std::string& s) {
    std::string o;
    for (char c : s)
        o += c == '<' ? "&lt;" : c == '>' ? "&gt;" : c == '&' ? "&amp;" : std::string(1, c);
    return o;
}

double median(std::vector<double> v) {
    if (v.empty())
        return 0.0;
    std::sort(v.begin(), v.end());
    const size_t n = v.size();
    return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

} // namespace focal
