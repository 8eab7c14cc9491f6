// The command line the simple benches share: --quick, --markdown, --help.
#pragma once

#include <cstdio>
#include <cstring>
#include <optional>

namespace pathstream::bench {

/// What the command line asked for.
struct BenchArgs {
    bool quick = false;     ///< the ctest smoke run
    bool markdown = false;  ///< tables in Markdown
};

/// Parses argv into `args`. Returns an exit status when the program should stop: 0 after
/// printing `usage` for --help, 2 after printing it to standard error for anything else.
inline std::optional<int> parse_bench_args(int argc, char** argv, const char* usage,
                                           BenchArgs& args) {
    for (int i = 1; i < argc; ++i) {
        if (std::strcmp(argv[i], "--quick") == 0) {
            args.quick = true;
        } else if (std::strcmp(argv[i], "--markdown") == 0) {
            args.markdown = true;
        } else if (std::strcmp(argv[i], "--help") == 0) {
            std::fputs(usage, stdout);
            return 0;
        } else {
            std::fputs(usage, stderr);
            return 2;
        }
    }
    return std::nullopt;
}

}  // namespace pathstream::bench
