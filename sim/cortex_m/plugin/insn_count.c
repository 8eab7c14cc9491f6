/*
 * insn_count: a QEMU TCG plugin (API version 1, qemu 7.2) that counts executed guest
 * instructions, in total and inside given address ranges, for instruction budgets.
 *
 *   qemu-system-arm ... -plugin libpathstream_insn_count.so[,ARG]...
 *
 * Arguments (each "key=value"; numbers in C syntax, e.g. 0x1f4 or 500):
 *   lo=A,hi=B      count instructions whose address is in [A, B) (one range)
 *   range=A:B      the same; may be repeated (up to 64 ranges, counted separately)
 *   mark=A         each time the instruction at address A executes, record a snapshot of
 *                  the total and of every range counter (up to 4096 snapshots)
 *   interval=A:B   the instructions executed from each execution of A to the next of B
 *                  (B's included, A's not): a function's cost per call, callees and any
 *                  interrupt taken meanwhile included, with A its entry and B the
 *                  instruction its caller returns to; kept per call (up to 2^24 calls)
 *   out=PATH       write the report to PATH instead of stderr
 *
 * Report, written when QEMU exits (e.g. through semihosting SYS_EXIT):
 *   insn_count total N
 *   insn_count range I LO HI N
 *   insn_count mark I TOTAL C0 C1 ...     (C_i: range i's counter at that moment)
 *   insn_count interval A B CALLS MIN MEDIAN P99 P999 MAX SUM
 *
 * Counting is exact: every instruction gets an inline 64-bit add before it executes,
 * including instructions inside IT blocks whose condition fails (they occupy an issue slot
 * on the core too). Single vCPU boards only (the counters are not per vCPU).
 */
#include <inttypes.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "qemu_plugin_api.h"

QEMU_PLUGIN_EXPORT int qemu_plugin_version = QEMU_PLUGIN_VERSION;

enum { kMaxRanges = 64, kMaxMarks = 4096 };

struct range {
    uint64_t lo, hi, count;
};

static uint64_t g_total;
static struct range g_ranges[kMaxRanges];
static int g_range_count;
static uint64_t g_lo, g_hi;
static int g_have_lo, g_have_hi;
static uint64_t g_mark_addr;
static int g_have_mark;
static uint64_t *g_snapshots; /* kMaxMarks rows of (1 + g_range_count) */
static unsigned g_mark_count;
static const char *g_out_path;
static int g_reported;
static uint64_t g_interval_a, g_interval_b;
static int g_have_interval, g_interval_open;
static uint64_t g_interval_start;
static uint64_t *g_interval_values;
static size_t g_interval_count, g_interval_capacity;
enum { kMaxIntervals = 1 << 24 };

static void on_interval_start(unsigned int vcpu_index, void *userdata) {
    (void)vcpu_index;
    (void)userdata;
    g_interval_open = 1;
    g_interval_start = g_total;
}

static void on_interval_end(unsigned int vcpu_index, void *userdata) {
    (void)vcpu_index;
    (void)userdata;
    if (!g_interval_open) return;
    g_interval_open = 0;
    if (g_interval_count == g_interval_capacity) {
        if (g_interval_capacity == kMaxIntervals) return;
        const size_t grown = g_interval_capacity == 0 ? 4096 : 2 * g_interval_capacity;
        uint64_t *v = realloc(g_interval_values, grown * sizeof *v);
        if (v == NULL) return;
        g_interval_values = v;
        g_interval_capacity = grown;
    }
    g_interval_values[g_interval_count++] = g_total - g_interval_start;
}

static int compare_u64(const void *a, const void *b) {
    const uint64_t x = *(const uint64_t *)a, y = *(const uint64_t *)b;
    return x < y ? -1 : x > y;
}

static void on_mark(unsigned int vcpu_index, void *userdata) {
    (void)vcpu_index;
    (void)userdata;
    if (g_mark_count < kMaxMarks) {
        uint64_t *row = g_snapshots + (size_t)g_mark_count * (size_t)(1 + g_range_count);
        row[0] = g_total;
        for (int i = 0; i < g_range_count; ++i) row[1 + i] = g_ranges[i].count;
    }
    ++g_mark_count;
}

static void on_tb_translate(qemu_plugin_id_t id, struct qemu_plugin_tb *tb) {
    (void)id;
    const size_t n = qemu_plugin_tb_n_insns(tb);
    for (size_t i = 0; i < n; ++i) {
        struct qemu_plugin_insn *insn = qemu_plugin_tb_get_insn(tb, i);
        const uint64_t vaddr = qemu_plugin_insn_vaddr(insn);
        qemu_plugin_register_vcpu_insn_exec_inline(insn, QEMU_PLUGIN_INLINE_ADD_U64, &g_total, 1);
        for (int r = 0; r < g_range_count; ++r) {
            if (vaddr >= g_ranges[r].lo && vaddr < g_ranges[r].hi) {
                qemu_plugin_register_vcpu_insn_exec_inline(insn, QEMU_PLUGIN_INLINE_ADD_U64,
                                                           &g_ranges[r].count, 1);
            }
        }
        if (g_have_mark && vaddr == g_mark_addr) {
            qemu_plugin_register_vcpu_insn_exec_cb(insn, on_mark, QEMU_PLUGIN_CB_NO_REGS, NULL);
        }
        if (g_have_interval && vaddr == g_interval_a) {
            qemu_plugin_register_vcpu_insn_exec_cb(insn, on_interval_start, QEMU_PLUGIN_CB_NO_REGS,
                                                   NULL);
        }
        if (g_have_interval && vaddr == g_interval_b) {
            qemu_plugin_register_vcpu_insn_exec_cb(insn, on_interval_end, QEMU_PLUGIN_CB_NO_REGS,
                                                   NULL);
        }
    }
}

static void report(void) {
    if (g_reported) return;
    g_reported = 1;
    FILE *out = stderr;
    if (g_out_path != NULL) {
        out = fopen(g_out_path, "w");
        if (out == NULL) {
            fprintf(stderr, "insn_count: cannot write %s\n", g_out_path);
            out = stderr;
        }
    }
    fprintf(out, "insn_count total %" PRIu64 "\n", g_total);
    for (int r = 0; r < g_range_count; ++r) {
        fprintf(out, "insn_count range %d 0x%" PRIx64 " 0x%" PRIx64 " %" PRIu64 "\n", r,
                g_ranges[r].lo, g_ranges[r].hi, g_ranges[r].count);
    }
    const unsigned marks = g_mark_count < kMaxMarks ? g_mark_count : kMaxMarks;
    for (unsigned m = 0; m < marks; ++m) {
        const uint64_t *row = g_snapshots + (size_t)m * (size_t)(1 + g_range_count);
        fprintf(out, "insn_count mark %u %" PRIu64, m, row[0]);
        for (int r = 0; r < g_range_count; ++r) fprintf(out, " %" PRIu64, row[1 + r]);
        fputc('\n', out);
    }
    if (g_mark_count > kMaxMarks) {
        fprintf(out, "insn_count marks_dropped %u\n", g_mark_count - kMaxMarks);
    }
    if (g_have_interval) {
        const size_t n = g_interval_count;
        uint64_t sum = 0;
        for (size_t i = 0; i < n; ++i) sum += g_interval_values[i];
        if (n > 0) qsort(g_interval_values, n, sizeof *g_interval_values, compare_u64);
#define PERCENTILE(p) (n > 0 ? g_interval_values[(size_t)((double)(n - 1) * (p))] : 0)
        fprintf(out,
                "insn_count interval 0x%" PRIx64 " 0x%" PRIx64 " %zu %" PRIu64 " %" PRIu64
                " %" PRIu64 " %" PRIu64 " %" PRIu64 " %" PRIu64 "\n",
                g_interval_a, g_interval_b, n, PERCENTILE(0.0), PERCENTILE(0.5), PERCENTILE(0.99),
                PERCENTILE(0.999), PERCENTILE(1.0), sum);
#undef PERCENTILE
    }
    if (out != stderr) fclose(out);
    else fflush(out);
}

static void on_exit_cb(qemu_plugin_id_t id, void *userdata) {
    (void)id;
    (void)userdata;
    report();
}

/* Parses a C number (decimal, 0x hex); returns 0 on success. */
static int parse_u64(const char *s, uint64_t *v) {
    char *end = NULL;
    if (*s == '\0') return -1;
    *v = strtoull(s, &end, 0);
    return *end == '\0' ? 0 : -1;
}

static int add_range(uint64_t lo, uint64_t hi) {
    if (g_range_count == kMaxRanges || hi < lo) return -1;
    g_ranges[g_range_count].lo = lo;
    g_ranges[g_range_count].hi = hi;
    g_ranges[g_range_count].count = 0;
    ++g_range_count;
    return 0;
}

QEMU_PLUGIN_EXPORT int qemu_plugin_install(qemu_plugin_id_t id, const qemu_info_t *info,
                                           int argc, char **argv) {
    (void)info;
    for (int i = 0; i < argc; ++i) {
        const char *arg = argv[i];
        const char *eq = strchr(arg, '=');
        if (eq == NULL) {
            fprintf(stderr, "insn_count: argument '%s' is not key=value\n", arg);
            return -1;
        }
        const size_t key_len = (size_t)(eq - arg);
        const char *value = eq + 1;
        int bad = 0;
        if (key_len == 2 && strncmp(arg, "lo", 2) == 0) {
            bad = parse_u64(value, &g_lo);
            g_have_lo = 1;
        } else if (key_len == 2 && strncmp(arg, "hi", 2) == 0) {
            bad = parse_u64(value, &g_hi);
            g_have_hi = 1;
        } else if (key_len == 5 && strncmp(arg, "range", 5) == 0) {
            char lo_text[32];
            const char *colon = strchr(value, ':');
            uint64_t lo = 0, hi = 0;
            if (colon == NULL || (size_t)(colon - value) >= sizeof lo_text) {
                bad = -1;
            } else {
                memcpy(lo_text, value, (size_t)(colon - value));
                lo_text[colon - value] = '\0';
                bad = parse_u64(lo_text, &lo) || parse_u64(colon + 1, &hi) || add_range(lo, hi);
            }
        } else if (key_len == 4 && strncmp(arg, "mark", 4) == 0) {
            bad = parse_u64(value, &g_mark_addr);
            g_have_mark = 1;
        } else if (key_len == 8 && strncmp(arg, "interval", 8) == 0) {
            char a_text[32];
            const char *colon = strchr(value, ':');
            if (colon == NULL || (size_t)(colon - value) >= sizeof a_text) {
                bad = -1;
            } else {
                memcpy(a_text, value, (size_t)(colon - value));
                a_text[colon - value] = '\0';
                bad = parse_u64(a_text, &g_interval_a) || parse_u64(colon + 1, &g_interval_b);
                g_have_interval = 1;
            }
        } else if (key_len == 3 && strncmp(arg, "out", 3) == 0) {
            g_out_path = value; /* argv stays valid for the plugin's lifetime */
        } else {
            bad = -1;
        }
        if (bad) {
            fprintf(stderr, "insn_count: bad argument '%s'\n", arg);
            return -1;
        }
    }
    if (g_have_lo != g_have_hi) {
        fprintf(stderr, "insn_count: lo= and hi= go together\n");
        return -1;
    }
    if (g_have_lo && add_range(g_lo, g_hi) != 0) {
        fprintf(stderr, "insn_count: bad range lo=0x%" PRIx64 " hi=0x%" PRIx64 "\n", g_lo, g_hi);
        return -1;
    }
    g_snapshots = calloc((size_t)kMaxMarks * (size_t)(1 + g_range_count), sizeof(uint64_t));
    if (g_snapshots == NULL) return -1;
    qemu_plugin_register_vcpu_tb_trans_cb(id, on_tb_translate);
    qemu_plugin_register_atexit_cb(id, on_exit_cb, NULL);
    return 0;
}
