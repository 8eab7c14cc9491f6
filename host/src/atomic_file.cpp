#include "pathstream/host/atomic_file.hpp"

#include <iostream>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <random>
#include <stdexcept>

namespace pathstream::host {

AtomicFile::AtomicFile(std::string path) : path_(std::move(path)) {
    std::random_device rd;
    temp_ = path_ + ".tmp-" + std::to_string(rd() % 1000000);
    out_.open(temp_, std::ios::binary | std::ios::trunc);
    if (!out_) {
        throw std::runtime_error(path_ + ": cannot create output file: " + std::strerror(errno));
    }
}

AtomicFile::~AtomicFile() {
    if (!committed_) {
        out_.close();
        std::remove(temp_.c_str());
    }
}

void AtomicFile::commit() {
    out_.flush();
    out_.close();
    if (!out_) throw std::runtime_error(path_ + ": write failed (disk full?)");
    if (std::rename(temp_.c_str(), path_.c_str()) != 0) {
        throw std::runtime_error(path_ + ": cannot rename output into place: " + std::strerror(errno));
    }
    committed_ = true;
}

void write_output(const std::string& output, const std::function<void(std::ostream&)>& write) {
    if (output.empty() || output == "-") {
        write(std::cout);
        std::cout.flush();
        if (!std::cout) throw std::runtime_error("standard output: write failed");
        return;
    }
    AtomicFile file(output);
    write(file.stream());
    file.commit();
}

}  // namespace pathstream::host
