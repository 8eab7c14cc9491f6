// The tick trace on USART2 (built with PATHSTREAM_FW_TRACE, for tests): every path tick's
// setpoints and pen, as lines of the CSV `pathstream device --record` writes ("tick,x,y,pen",
// then "k,x,y,pen" per path tick), and notes starting with '#'. The tick interrupt only queues
// a record; the task formats and sends it, so the interrupt never waits for the UART.
#pragma once

#include <atomic>
#include <cstddef>
#include <cstdint>

#include "pathstream/span_queue.hpp"
#include "pathstream/units.hpp"
#include "registers.hpp"
#include "usart.hpp"

namespace firmware {

template <unsigned Axes>
class Trace {
public:
    /// The CSV header and a note naming the build. Task context, before the tick starts.
    void header(bool qemu, std::uint32_t baud, std::uint32_t unit) {
        static const char* const names[] = {"x", "y", "z", "a"};
        text("# pathstream firmware stm32f405");
        text(qemu ? " qemu" : " board");
        text(" axes ");
        number(Axes);
        text(" modbus-rtu 8E1 baud ");
        number(baud);
        text(" unit ");
        number(unit);
        text("\ntick");
        for (unsigned a = 0; a < Axes; ++a) {
            text(",");
            text(names[a]);
        }
        text(",pen\n");
        flush();
    }

    /// Queues one path tick. Tick interrupt; a full queue drops the record and counts it.
    void record(const pathstream::Lsb (&position)[Axes], bool pen) {
        Record* r = records_.claim();
        if (r == nullptr) {
            lost_.store(lost_.load(std::memory_order_relaxed) + 1, std::memory_order_relaxed);
            return;
        }
        for (unsigned a = 0; a < Axes; ++a) r->position[a] = position[a];
        r->pen = pen;
        records_.publish();
    }

    /// Sends every queued record, and a note when records were lost. Task context.
    void drain() {
        while (const Record* r = records_.front()) {
            number(next_++);
            for (unsigned a = 0; a < Axes; ++a) {
                text(",");
                number(r->position[a]);
            }
            text(r->pen ? ",1\n" : ",0\n");
            records_.release();
            flush();
        }
        const std::uint32_t lost = lost_.load(std::memory_order_relaxed);
        if (lost != lost_reported_) {
            lost_reported_ = lost;
            note("trace_lost", lost, 0);
        }
    }

    /// A note line "# name value [of total]". Task context.
    void note(const char* name, std::uint32_t value, std::uint32_t total) {
        text("# ");
        text(name);
        text(" ");
        number(value);
        if (total != 0) {
            text(" of ");
            number(total);
        }
        text("\n");
        flush();
    }

    /// A note line "# name axis value" (axis 0.. as x, y, z, a). Task context.
    void note_axis(const char* name, unsigned axis, std::int64_t value) {
        static const char* const names[] = {"x", "y", "z", "a"};
        text("# ");
        text(name);
        text(" ");
        text(names[axis]);
        text(" ");
        number(value);
        text("\n");
        flush();
    }

private:
    struct Record {
        pathstream::Lsb position[Axes];
        bool pen;
    };

    void text(const char* s) {
        while (*s != '\0' && used_ < sizeof line_) line_[used_++] = static_cast<std::uint8_t>(*s++);
    }
    void number(std::int64_t v) {
        char digits[20];
        unsigned n = 0;
        std::uint64_t u =
            v < 0 ? 0u - static_cast<std::uint64_t>(v) : static_cast<std::uint64_t>(v);
        do {
            digits[n++] = static_cast<char>('0' + u % 10u);
            u /= 10u;
        } while (u != 0 && n < sizeof digits);
        if (v < 0 && used_ < sizeof line_) line_[used_++] = '-';
        while (n > 0 && used_ < sizeof line_)
            line_[used_++] = static_cast<std::uint8_t>(digits[--n]);
    }
    void flush() {
        UsartPort<stm32::kUsart2>::write(line_, used_);
        used_ = 0;
    }

    pathstream::SpanQueue<Record, 512> records_;  // producer: tick interrupt; consumer: task
    std::atomic<std::uint32_t> lost_{0};          // tick interrupt only
    std::uint32_t lost_reported_ = 0;             // task only
    std::uint64_t next_ = 0;                      // task only
    std::uint8_t line_[160] = {};                 // task only
    std::size_t used_ = 0;                        // task only
};

}  // namespace firmware
