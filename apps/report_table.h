// A report table: a header and rows of text cells, written as Markdown (equal_error.md, the
// bench's stdout) or as an HTML table (index.html). The caller owns the table and the text.
#pragma once

#include <string>
#include <vector>

namespace focal {

struct Table {
    std::vector<std::string> header;
    std::vector<std::vector<std::string>> rows; // each as many cells as the header
};

// Columns padded to their widest cell, a rule under the header.
std::string markdownTable(const Table& t);

// Cells HTML-escaped.
std::string htmlTable(const Table& t);

} // namespace focal
