// Small text helpers shared by the commands' reports (`focal bench`, `focal render --stats`):
// file-safe names, printf-style numbers, HTML escaping and the median of timings. Pure
// functions; every result is a string or value the caller owns.
#pragma once

#include <string>
#include <vector>

namespace focal {

// `text` with every character but [A-Za-z0-9.-] replaced by '_', for file names.
std::string safeName(const std::string& text);

// One number through a printf format with one conversion, e.g. fmt("%.1f ms", 3.14).
std::string fmt(const char* format, double v);

// A float with 9 significant digits: read back, it gives the same float (command-line options).
std::string exactText(float v);

// <, > and & as HTML entities.
std::string htmlEscape(const std::string& s);

// The median (the mean of the two middle values for an even count); 0 for no values.
double median(std::vector<double> v);

} // namespace focal
