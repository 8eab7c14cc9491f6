// The exit statuses of every pathstream command (docs/cli.md, "Exit codes"), declared once.
#pragma once

namespace pathstream::host {

inline constexpr int kExitOk = 0;
inline constexpr int kExitInput = 1;     ///< a bad input file: path or machine profile
inline constexpr int kExitUsage = 2;     ///< a bad command line
inline constexpr int kExitOutput = 3;    ///< output could not be written
inline constexpr int kExitInternal = 4;  ///< a bug; `sim` also when the simulated device ran dry
inline constexpr int kExitPlanning =
    5;  ///< the machine's limits cannot be met, or a plan failed its check
inline constexpr int kExitDevice = 6;       ///< device, bus or link failure
inline constexpr int kExitInterrupted = 7;  ///< `stream` interrupted; its journal resumes it

}  // namespace pathstream::host
