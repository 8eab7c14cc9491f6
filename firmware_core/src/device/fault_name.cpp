#include "pathstream/device/gpio_logic.hpp"

namespace pathstream::device {
namespace {

// Appends to a bounded buffer, always leaving room for the NUL (freestanding: no snprintf).
class Writer {
public:
    Writer(char* out, std::size_t capacity) : out_(out), capacity_(capacity) {}
    void put(char c) {
        if (capacity_ != 0 && length_ + 1 < capacity_) out_[length_++] = c;
    }
    void put(const char* s) {
        while (*s != '\0') put(*s++);
    }
    void put_unsigned(unsigned v) {
        char digits[12];
        std::size_t n = 0;
        do {
            digits[n++] = static_cast<char>('0' + v % 10u);
            v /= 10u;
        } while (v != 0);
        while (n != 0) put(digits[--n]);
    }
    void put_hex4(unsigned v) {
        const char* hex = "0123456789abcdef";
        for (int shift = 12; shift >= 0; shift -= 4)
            put(hex[(v >> static_cast<unsigned>(shift)) & 0xFu]);
    }
    std::size_t finish() {
        if (capacity_ != 0) out_[length_] = '\0';
        return length_;
    }

private:
    char* out_;
    std::size_t capacity_;
    std::size_t length_ = 0;
};

}  // namespace

std::size_t fault_name(FaultCode code, char* out, std::size_t capacity) {
    Writer w(out, capacity);
    unsigned axis = 0;
    LimitSide side = LimitSide::kNegative;
    if (code == FaultCode::kNone) {
        w.put("none");
    } else if (code == FaultCode::kExternal) {
        w.put("external fault");
    } else if (code == FaultCode::kStopFailed) {
        w.put("no controlled stop fits in one span");
    } else if (code == FaultCode::kReentryFailed) {
        w.put("no move back onto the path fits in one span");
    } else if (code == FaultCode::kOutputFailed) {
        w.put("a machine output could not be switched");
    } else if (limit_fault_switch(code, axis, side)) {
        const char* names = "xyzabcuv";
        const bool negative = side == LimitSide::kNegative;
        w.put("limit switch ");
        w.put(names[axis]);
        w.put(negative ? '-' : '+');
        w.put(" (axis ");
        w.put_unsigned(axis);
        w.put(negative ? ", negative side)" : ", positive side)");
    } else {
        w.put("fault 0x");
        w.put_hex4(static_cast<unsigned>(code));
    }
    return w.finish();
}

}  // namespace pathstream::device
