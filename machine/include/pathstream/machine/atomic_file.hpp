// Output files that appear whole or not at all.
#pragma once

#include <fstream>
#include <functional>
#include <ostream>
#include <string>

namespace pathstream::host {

/// Writes to "PATH.tmp-PID" and renames onto PATH in commit(); a writer destroyed without
/// commit() (an error, an exception) removes its temporary file, so PATH is never half-written.
/// A SIGINT, SIGTERM or SIGHUP that would end the process while the file is open (no other
/// handler installed) removes it too, then ends the process as the signal would have. One
/// AtomicFile at a time per process has that protection (the commands write one at a time);
/// construct and destroy it from the main thread. A PATH that is a device or a pipe
/// (/dev/null, a FIFO) is written in place: there is nothing to replace atomically.
class AtomicFile {
public:
    explicit AtomicFile(std::string path);
    ~AtomicFile();
    AtomicFile(const AtomicFile&) = delete;
    AtomicFile& operator=(const AtomicFile&) = delete;

    std::ostream& stream() { return out_; }
    /// Flushes, checks for write errors and renames into place. Throws std::runtime_error.
    void commit();

private:
    std::string path_;
    std::string temp_;
    std::ofstream out_;
    bool committed_ = false;
    bool direct_ = false;   ///< PATH is a device or a pipe: written in place
    bool guarded_ = false;  ///< this file's temporary name is the one the signal handler removes
};

/// Runs `write` on standard output when `output` is "-" (or empty: the command's default
/// there), else on an AtomicFile committed after it returns. Throws std::runtime_error when
/// the write fails; an exception from `write` leaves no file.
void write_output(const std::string& output, const std::function<void(std::ostream&)>& write);

}  // namespace pathstream::host
