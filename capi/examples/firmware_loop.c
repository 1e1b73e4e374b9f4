/*
 * A controller written in C, driving the simulated drive in a loop as drive firmware does:
 * read the sensors at 20 kHz, decide the heater command, repeat. The same controller as the
 * Rust example examples/firmware_loop.rs, decision for decision: it ramps the heater slowly
 * and watches the acoustic emission, learns the AE baseline and its scatter over the first
 * 2 ms, declares touchdown once a 1 ms running mean of the AE is six standard errors above
 * that baseline, then backs off 10 mW and holds there for 10 ms. It prints what it saw and
 * compares its touchdown with the static model's.
 *
 *   firmware_loop [SEED] [--trace FILE]
 *
 * --trace writes every period (the command held and the sensors read) to FILE as CSV, with 17
 * significant digits: the Rust example writes the same file, and capi/tests/c_example.rs
 * checks that the two agree to the bit.
 *
 * Build (from the repository root, after `cargo build --manifest-path capi/Cargo.toml`):
 *   cc -std=c99 -O2 -ffp-contract=off -Icapi/include capi/examples/firmware_loop.c \
 *      target/debug/libhdi.a -lm -lpthread -ldl -o firmware_loop
 * -ffp-contract=off keeps the compiler from fusing a*b+c into one rounding, so the
 * controller's arithmetic is the Rust example's to the bit.
 */
#define _POSIX_C_SOURCE 199309L
#include <math.h>
#include <stdbool.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "hdi.h"

/* Controller period (s): 20 kHz. */
static const double DT = 50e-6;
/* Periods of the AE baseline (2 ms). */
static const size_t BASELINE_PERIODS = 40;
/* Periods of the running mean (1 ms). */
static const double MEAN_PERIODS = 20.0;

/* Prints the failed call, its status and the library's message, and exits. */
#define CHECK(call)                                                                           \
    do {                                                                                      \
        HdiStatus status_ = (call);                                                           \
        if (status_ != HDI_STATUS_OK) {                                                       \
            fprintf(stderr, "%s: %s: %s\n", #call, hdi_status_name(status_), hdi_last_error()); \
            exit(1);                                                                          \
        }                                                                                     \
    } while (0)

/* The user's controller: ramp, watch the AE, back off, hold. */
typedef struct {
    double power_mw;    /* heater now (mW) */
    double ramp_mw;     /* ramp per period (mW) */
    size_t n;           /* periods seen */
    double base_sum;    /* baseline sums over the first periods */
    double base_sum2;
    size_t base_n;
    double mean;        /* running mean of the AE (exponential, 1 ms) */
    bool touched;
    double touchdown_mw;
    size_t hold_left;
} RampAndWatch;

static HdiCommand heater_mw(double mw) {
    HdiCommand c = {0};
    c.heater_power_mw = mw;
    return c;
}

/* The command for the first period. */
static HdiCommand start(const RampAndWatch *c) { return heater_mw(c->power_mw); }

/* Reads the sensors of the period just ended; false: stop, else the next command. */
static bool update(RampAndWatch *c, const HdiSensors *s, HdiCommand *next) {
    c->n += 1;
    if (c->touched) {
        /* Backed off: hold for a while, then stop. */
        c->hold_left = c->hold_left > 0 ? c->hold_left - 1 : 0;
        if (c->hold_left == 0) {
            return false;
        }
        *next = heater_mw(c->touchdown_mw - 10.0);
        return true;
    }
    if (c->n <= BASELINE_PERIODS) {
        c->base_sum += s->acoustic_v;
        c->base_sum2 += s->acoustic_v * s->acoustic_v;
        c->base_n += 1;
        c->mean = s->acoustic_v;
        *next = heater_mw(c->power_mw);
        return true;
    }
    const double a = 1.0 / MEAN_PERIODS;
    c->mean += a * (s->acoustic_v - c->mean);
    const double k = (double)c->base_n;
    const double m = c->base_sum / k;
    const double var = c->base_sum2 / k - m * m;
    const double sd = sqrt(var > 0.0 ? var : 0.0);
    /* Standard error of an exponential mean of white samples: sd * sqrt(a / (2 - a)). */
    const double se = sd * sqrt(a / (2.0 - a));
    if (c->mean > m + 6.0 * se) {
        c->touched = true;
        c->touchdown_mw = c->power_mw;
        c->hold_left = 200;
        *next = heater_mw(c->power_mw - 10.0);
        return true;
    }
    c->power_mw += c->ramp_mw;
    *next = heater_mw(c->power_mw);
    return true;
}

static double seconds_now(void) {
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

int main(int argc, char **argv) {
    uint64_t seed = 1;
    const char *trace_path = NULL;
    for (int i = 1; i < argc; i++) {
        if (strcmp(argv[i], "--trace") == 0 && i + 1 < argc) {
            trace_path = argv[++i];
        } else {
            seed = strtoull(argv[i], NULL, 10);
        }
    }
    if (hdi_abi_version() != HDI_ABI_VERSION) {
        fprintf(stderr, "built against ABI %d, running with ABI %u\n", HDI_ABI_VERSION,
                hdi_abi_version());
        return 1;
    }
    FILE *trace = NULL;
    if (trace_path != NULL) {
        trace = fopen(trace_path, "w");
        if (trace == NULL) {
            perror(trace_path);
            return 1;
        }
        fprintf(trace, "period,time_s,heater_power_mw,contact_resistance_ohm,acoustic_v,"
                       "readback_fundamental_v,readback_third_v,true_gap_nm,"
                       "true_mean_contact_force_un,true_sensor_temperature_k,"
                       "true_disk_height_nm\n");
    }

    /* The paper scene in the zone at 25 mm, the default disk and sensors (NULL config). */
    HdiScene *scene = NULL;
    HdiDrive *drive = NULL;
    CHECK(hdi_scene_paper(&scene));
    CHECK(hdi_drive_new(scene, NULL, seed, &drive));
    /* The drive owns what it needs: the scene can go now. */
    CHECK(hdi_scene_free(scene));

    RampAndWatch ctrl = {0};
    ctrl.power_mw = 70.0;
    ctrl.ramp_mw = 0.05; /* 1 mW/ms: 0.05 mW per 50 us period */

    const double clock0 = seconds_now();
    HdiCommand command = start(&ctrl);
    HdiSensors s;
    size_t periods = 0;
    for (size_t n = 1; n <= 1000000; n++) {
        CHECK(hdi_drive_step(drive, &command, DT, &s));
        if (trace != NULL) {
            fprintf(trace, "%zu,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g\n", n,
                    s.time_s, s.heater_power_mw, s.contact_resistance_ohm, s.acoustic_v,
                    s.readback_fundamental_v, s.readback_third_v, s.truth.gap_nm,
                    s.truth.mean_contact_force_un, s.truth.sensor_temperature_k,
                    s.truth.disk_height_nm);
        }
        if (!update(&ctrl, &s, &command)) {
            periods = n;
            break;
        }
    }
    const double wall = seconds_now() - clock0;
    if (periods == 0) {
        fprintf(stderr, "the controller did not stop within 1000000 periods\n");
        return 1;
    }

    /* The static touchdown of the drive's own model (its zone and heater). */
    HdiModel *model = NULL;
    HdiHysteresis h;
    CHECK(hdi_drive_model(drive, &model));
    CHECK(hdi_model_hysteresis(model, NULL, &h));

    double time_s = 0.0;
    CHECK(hdi_drive_time(drive, &time_s));
    printf("seed %llu: %zu periods (%.1f ms of drive time) in %.1f ms\n", (unsigned long long)seed,
           periods, time_s * 1e3, wall * 1e3);
    if (ctrl.touched) {
        printf("AE touchdown at %.2f mW (static touchdown %.3f mW: %+.2f mW); holding %.2f mW\n",
               ctrl.touchdown_mw, h.touchdown.power_mw, ctrl.touchdown_mw - h.touchdown.power_mw,
               ctrl.touchdown_mw - 10.0);
    } else {
        printf("no touchdown seen\n");
    }

    CHECK(hdi_model_free(model));
    CHECK(hdi_drive_free(drive));
    if (trace != NULL && fclose(trace) != 0) {
        perror(trace_path);
        return 1;
    }
    return 0;
}
