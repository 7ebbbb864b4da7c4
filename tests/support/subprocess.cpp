#include "support/subprocess.h"

#include <raster/check.h>

#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fcntl.h>
#include <fstream>
#include <sstream>
#include <sys/wait.h>
#include <unistd.h>

namespace focal::test {

namespace {

// Reads and deletes a temporary capture file.
std::string slurpAndRemove(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    std::ostringstream s;
    s << in.rdbuf();
    std::remove(path.c_str());
    return s.str();
}

std::string makeCaptureFile() {
    const char* tmpdir = std::getenv("TMPDIR");
    std::string pattern =
        std::string(tmpdir && *tmpdir ? tmpdir : "/tmp") + "/focal-capture-XXXXXX";
    const int fd = ::mkstemp(pattern.data());
    FOCAL_CHECK(fd >= 0);
    ::close(fd);
    return pattern;
}

} // namespace

ProcessResult runProcess(const std::vector<std::string>& argv, const std::string& cwd) {
    FOCAL_CHECK(!argv.empty());
    const std::string out_path = makeCaptureFile();
    const std::string err_path = makeCaptureFile();
    std::vector<char*> args;
    for (const std::string& a : argv)
        args.push_back(const_cast<char*>(a.c_str()));
    args.push_back(nullptr);

    std::fflush(stdout);
    std::fflush(stderr);
    const pid_t pid = ::fork();
    FOCAL_CHECK(pid >= 0);
    if (pid == 0) {
        // Child: only async-signal-safe calls until exec.
        const int in = ::open("/dev/null", O_RDONLY);
        const int out = ::open(out_path.c_str(), O_WRONLY | O_TRUNC);
        const int err = ::open(err_path.c_str(), O_WRONLY | O_TRUNC);
        if (in < 0 || out < 0 || err < 0 || ::dup2(in, 0) < 0 || ::dup2(out, 1) < 0 ||
            ::dup2(err, 2) < 0)
            ::_exit(125);
        if (!cwd.empty() && ::chdir(cwd.c_str()) != 0)
            ::_exit(126);
        ::execv(args[0], args.data());
        ::_exit(127);
    }
    int status = 0;
    while (::waitpid(pid, &status, 0) < 0)
        FOCAL_CHECK(errno == EINTR);
    ProcessResult result;
    if (WIFEXITED(status))
        result.exit_code = WEXITSTATUS(status);
    else if (WIFSIGNALED(status))
        result.exit_code = 128 + WTERMSIG(status);
    result.out = slurpAndRemove(out_path);
    result.err = slurpAndRemove(err_path);
    return result;
}

std::vector<std::string> splitLines(const std::string& text) {
    std::vector<std::string> lines;
    size_t start = 0;
    while (start < text.size()) {
        size_t end = text.find('\n', start);
        if (end == std::string::npos)
            end = text.size();
        lines.push_back(text.substr(start, end - start));
        start = end + 1;
    }
    return lines;
}

} // namespace focal::test
