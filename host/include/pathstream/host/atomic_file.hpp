// Output files that appear whole or not at all.
#pragma once

#include <fstream>
#include <functional>
#include <ostream>
#include <string>

namespace pathstream::host {

/// Writes to "PATH.tmp-XXXX" and renames onto PATH in commit(); a writer destroyed without
/// commit() (an error, an exception) removes its temporary file, so PATH is never half-written.
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
};

/// Runs `write` on standard output when `output` is "-" (or empty: the command's default
/// there), else on an AtomicFile committed after it returns. Throws std::runtime_error when
/// the write fails; an exception from `write` leaves no file.
void write_output(const std::string& output, const std::function<void(std::ostream&)>& write);

}  // namespace pathstream::host
