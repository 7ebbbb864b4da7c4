// libFuzzer target: `focal render`'s option parsing and lens validation. The input is a list of
// arguments separated by newlines, appended to `focal render builtin:demo -o fuzz.png
// --dry-run --memory-budget 256M`: everything up to the lens samples and the memory check runs,
// nothing is rendered or written. Any crash or sanitizer report is a bug: bad options must give
// exit code 1 or 2 with a message. Seeds: tests/fuzz/corpus/cli; see docs/testing.md.
#include "apps/cli.h"

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    std::vector<std::string> args = {"focal",    "render",    "builtin:demo",    "-o",
                                     "fuzz.png", "--dry-run", "--memory-budget", "256M"};
    std::string token;
    for (size_t i = 0; i < size; ++i) {
        const char c = char(data[i]);
        if (c == '\n') {
            args.push_back(token);
            token.clear();
        } else if (c != '\0') {
            token.push_back(c);
        }
    }
    if (!token.empty())
        args.push_back(token);
    std::vector<char*> argv;
    for (std::string& a : args)
        argv.push_back(a.data());
    argv.push_back(nullptr);
    (void)focal::runCli(int(argv.size() - 1), argv.data());
    return 0;
}
