// Runs a command line in a shell (runCommand), or rlpbrt's (runCli: RLPBRT_BINARY), and
// captures its exit status and its output (stdout and stderr together).
#pragma once

#include <sys/wait.h>

#include <cstdio>
#include <string>

namespace rlpbrt::test {

struct CliRun {
    int status = -1;  // exit status; -1 when the process did not exit normally
    std::string output;
};

inline CliRun runCommand(const std::string& command) {
    CliRun r;
    const std::string cmd = command + " 2>&1";
    FILE* p = popen(cmd.c_str(), "r");
    if (!p) return r;
    char buf[4096];
    size_t n;
    while ((n = fread(buf, 1, sizeof(buf), p)) > 0) r.output.append(buf, n);
    int st = pclose(p);
    r.status = WIFEXITED(st) ? WEXITSTATUS(st) : -1;
    return r;
}

inline CliRun runCli(const std::string& args) {
    return runCommand(std::string(RLPBRT_BINARY) + " " + args);
}

}  // namespace rlpbrt::test
