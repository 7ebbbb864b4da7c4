#include "apps/report_table.h"

#include "apps/report_text.h"

#include <algorithm>

namespace focal {

std::string markdownTable(const Table& t) {
    std::vector<size_t> width(t.header.size(), 3);
    for (size_t c = 0; c < t.header.size(); ++c) {
        width[c] = std::max(width[c], t.header[c].size());
        for (const auto& row : t.rows)
            width[c] = std::max(width[c], row[c].size());
    }
    auto line = [&](const std::vector<std::string>& cells) {
        std::string s = "|";
        for (size_t c = 0; c < cells.size(); ++c)
            s += " " + cells[c] + std::string(width[c] - cells[c].size(), ' ') + " |";
        return s + "\n";
    };
    std::vector<std::string> rule;
    for (size_t w : width)
        rule.push_back(std::string(w, '-'));
    std::string out = line(t.header) + line(rule);
    for (const auto& row : t.rows)
        out += line(row);
    return out;
}

std::string htmlTable(const Table& t) {
    std::string out = "<table border='1'><tr>";
    for (const std::string& h : t.header)
        out += "<th>" + htmlEscape(h) + "</th>";
    out += "</tr>";
    for (const auto& row : t.rows) {
        out += "<tr>";
        for (const std::string& cell : row)
            out += "<td>" + htmlEscape(cell) + "</td>";
        out += "</tr>";
    }
    return out + "</table>";
}

} // namespace focal
