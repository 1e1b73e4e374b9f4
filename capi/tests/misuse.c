/*
 * Misuses of the C ABI, each refused with its status and a message naming what was wrong;
 * run by tests/c_example.rs, also under valgrind (no invalid access, no leak, even for freed
 * and foreign handles).
 *
 *   misuse BAD_SCENE.toml    (a scene file whose nominal_clearance_nm is negative)
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "hdi.h"

static int failures = 0;

/* Checks that `got` is `want` and that the last error mentions `needle`. */
static void expect(const char *what, HdiStatus got, HdiStatus want, const char *needle) {
    const char *msg = hdi_last_error();
    if (got != want) {
        printf("FAIL %s: %s, expected %s (%s)\n", what, hdi_status_name(got), hdi_status_name(want),
               msg);
        failures++;
    } else if (needle != NULL && strstr(msg, needle) == NULL) {
        printf("FAIL %s: message \"%s\" does not mention \"%s\"\n", what, msg, needle);
        failures++;
    } else if (want == HDI_STATUS_OK && msg[0] != '\0') {
        printf("FAIL %s: a message after success: \"%s\"\n", what, msg);
        failures++;
    }
}

static void require(const char *what, int ok) {
    if (!ok) {
        printf("FAIL %s\n", what);
        failures++;
    }
}

int main(int argc, char **argv) {
    if (argc < 2) {
        fprintf(stderr, "usage: misuse BAD_SCENE.toml\n");
        return 2;
    }
    require("ABI version", hdi_abi_version() == HDI_ABI_VERSION);
    require("version", strlen(hdi_version()) > 0);

    /* Scenes: a bad file names the field as the file wrote it; bad text; NULL arguments. */
    HdiScene *scene = (HdiScene *)&failures; /* set to NULL on failure */
    expect("scene file", hdi_scene_from_file(argv[1], &scene), HDI_STATUS_INVALID_INPUT,
           "nominal_clearance_nm");
    require("scene NULL after failure", scene == NULL);
    expect("scene text", hdi_scene_from_toml("name = [", &scene), HDI_STATUS_SCENE, NULL);
    expect("scene missing file", hdi_scene_from_file("/nonexistent/scene.toml", &scene),
           HDI_STATUS_IO, "/nonexistent/scene.toml");
    expect("scene NULL text", hdi_scene_from_json(NULL, &scene), HDI_STATUS_NULL_POINTER, "json");
    expect("scene NULL out", hdi_scene_paper(NULL), HDI_STATUS_NULL_POINTER, "out");
    expect("scene", hdi_scene_paper(&scene), HDI_STATUS_OK, NULL);

    /* A drive with a config the library refuses, named as the config's field. */
    HdiDriveConfig config;
    expect("config default", hdi_drive_config_default(&config), HDI_STATUS_OK, NULL);
    HdiDrive *drive = NULL;
    config.sensors.contact.noise_ohm = -1.0;
    expect("config noise", hdi_drive_new(scene, &config, 1, &drive), HDI_STATUS_INVALID_INPUT,
           "config.sensors.contact.noise_ohm");
    hdi_drive_config_default(&config);
    config.atol_flight_pm = 0.001;
    expect("config atol", hdi_drive_new(scene, &config, 1, &drive), HDI_STATUS_INVALID_INPUT,
           "config.atol_flight_pm");
    hdi_drive_config_default(&config);
    config.disk.harmonic_count = 1;
    config.disk.harmonics = NULL;
    expect("config harmonics", hdi_drive_new(scene, &config, 1, &drive), HDI_STATUS_NULL_POINTER,
           "config.disk.harmonics");
    hdi_drive_config_default(&config);
    config.disk.random_order_max = 900;
    expect("config orders", hdi_drive_new(scene, &config, 1, &drive), HDI_STATUS_INVALID_INPUT,
           "config.disk");
    require("drive NULL after failure", drive == NULL);

    /* A drive of two heads: stepped with both commands at once, one clock. */
    hdi_drive_config_default(&config);
    config.heads = 33;
    expect("too many heads", hdi_drive_new(scene, &config, 1, &drive), HDI_STATUS_INVALID_INPUT,
           "config.heads");
    config.heads = 2;
    expect("two heads", hdi_drive_new(scene, &config, 1, &drive), HDI_STATUS_OK, NULL);
    HdiCommand two[2] = {{60.0, 0.0, 0.0, 0.0}, {60.0, 0.0, 0.0, 0.0}};
    HdiSensors s2[2];
    uint32_t heads = 0;
    expect("heads", hdi_drive_heads(drive, &heads), HDI_STATUS_OK, NULL);
    require("two heads counted", heads == 2);
    expect("one step on two heads", hdi_drive_step(drive, &two[0], 50e-6, &s2[0]),
           HDI_STATUS_INVALID_INPUT, "hdi_drive_step_heads");
    expect("wrong count", hdi_drive_step_heads(drive, two, 3, 50e-6, s2), HDI_STATUS_INVALID_INPUT,
           "count");
    two[1].heater_power_mw = NAN;
    expect("NaN on head 1", hdi_drive_step_heads(drive, two, 2, 50e-6, s2),
           HDI_STATUS_INVALID_INPUT, "commands[1].heater_power_mw");
    two[1].heater_power_mw = 61.0;
    expect("NULL sensors of heads", hdi_drive_step_heads(drive, two, 2, 50e-6, NULL),
           HDI_STATUS_NULL_POINTER, "sensors");
    expect("step heads", hdi_drive_step_heads(drive, two, 2, 50e-6, s2), HDI_STATUS_OK, NULL);
    require("one clock", s2[0].time_s == 50e-6 && s2[1].time_s == 50e-6);
    HdiModel *head_model = NULL;
    expect("head past the last", hdi_drive_head_model(drive, 2, &head_model),
           HDI_STATUS_INVALID_INPUT, "head");
    require("head model NULL after failure", head_model == NULL);
    expect("two heads free", hdi_drive_free(drive), HDI_STATUS_OK, NULL);
    drive = NULL;

    /* A drive, a model; commands the library refuses, named as the command's fields. */
    HdiModel *model = NULL;
    expect("drive", hdi_drive_new(scene, NULL, 1, &drive), HDI_STATUS_OK, NULL);
    expect("model", hdi_model_new(scene, &model), HDI_STATUS_OK, NULL);
    expect("scene free", hdi_scene_free(scene), HDI_STATUS_OK, NULL);
    HdiCommand cmd = {0};
    HdiSensors s;
    cmd.heater_power_mw = -1.0;
    expect("negative heater", hdi_drive_step(drive, &cmd, 50e-6, &s), HDI_STATUS_INVALID_INPUT,
           "command.heater_power_mw");
    cmd.heater_power_mw = 2000.0;
    expect("heater too high", hdi_drive_step(drive, &cmd, 50e-6, &s), HDI_STATUS_INVALID_INPUT,
           "command.heater_power_mw: must not exceed 1000 mW");
    cmd.heater_power_mw = 60.0;
    cmd.ac_frequency_khz = NAN;
    expect("NaN frequency", hdi_drive_step(drive, &cmd, 50e-6, &s), HDI_STATUS_INVALID_INPUT,
           "command.ac_frequency_khz");
    cmd.ac_frequency_khz = 0.0;
    expect("zero period", hdi_drive_step(drive, &cmd, 0.0, &s), HDI_STATUS_INVALID_INPUT,
           "period_s");
    expect("long period", hdi_drive_step(drive, &cmd, 2.0, &s), HDI_STATUS_INVALID_INPUT,
           "period_s");
    expect("NULL command", hdi_drive_step(drive, NULL, 50e-6, &s), HDI_STATUS_NULL_POINTER,
           "command");
    expect("NULL sensors", hdi_drive_step(drive, &cmd, 50e-6, NULL), HDI_STATUS_NULL_POINTER,
           "sensors");
    expect("step", hdi_drive_step(drive, &cmd, 50e-6, &s), HDI_STATUS_OK, NULL);
    require("time after one step", s.time_s == 50e-6);
    require("flying at 60 mW", s.truth.gap_nm > 1.0 && s.truth.gap_nm < 10.0);

    /* Handles of the wrong type, NULL, foreign and freed. */
    expect("model as drive", hdi_drive_step((HdiDrive *)model, &cmd, 50e-6, &s),
           HDI_STATUS_WRONG_HANDLE_TYPE, "a model handle where a drive handle is expected");
    expect("drive as model", hdi_model_free((HdiModel *)drive), HDI_STATUS_WRONG_HANDLE_TYPE,
           "model");
    expect("NULL drive", hdi_drive_step(NULL, &cmd, 50e-6, &s), HDI_STATUS_NULL_POINTER, "drive");
    double local = 0.0;
    expect("foreign pointer", hdi_drive_step((HdiDrive *)&local, &cmd, 50e-6, &s),
           HDI_STATUS_INVALID_HANDLE, "not a live drive handle");
    expect("free foreign", hdi_scene_free((HdiScene *)&local), HDI_STATUS_INVALID_HANDLE, "scene");
    expect("free NULL", hdi_drive_free(NULL), HDI_STATUS_OK, NULL);
    expect("drive free", hdi_drive_free(drive), HDI_STATUS_OK, NULL);
    expect("step freed", hdi_drive_step(drive, &cmd, 50e-6, &s), HDI_STATUS_INVALID_HANDLE,
           "already freed");
    expect("double free", hdi_drive_free(drive), HDI_STATUS_INVALID_HANDLE, "drive");
    expect("model free", hdi_model_free(model), HDI_STATUS_OK, NULL);
    expect("scene used after free", hdi_model_new(scene, &model), HDI_STATUS_INVALID_HANDLE,
           "scene");
    require("model NULL after failure", model == NULL);
    expect("NULL scene", hdi_drive_new(NULL, NULL, 1, &drive), HDI_STATUS_NULL_POINTER, "scene");

    /* A model outlives its scene; static analyses and bad options. */
    HdiScene *paper = NULL;
    hdi_scene_paper(&paper);
    hdi_model_new(paper, &model);
    hdi_scene_free(paper);
    HdiHysteresis h;
    expect("hysteresis", hdi_model_hysteresis(model, NULL, &h), HDI_STATUS_OK, NULL);
    require("touchdown above take-off", h.touchdown.power_mw > h.takeoff.power_mw);
    require("hysteresis", fabs(h.hysteresis_mw - (h.touchdown.power_mw - h.takeoff.power_mw)) < 1e-9);
    HdiStaticOptions opts;
    expect("static defaults", hdi_static_options_default(model, &opts), HDI_STATUS_OK, NULL);
    require("threshold 50 uN", opts.contact_threshold_un == 50.0);
    HdiTransition td;
    expect("touchdown", hdi_model_touchdown(model, &opts, &td), HDI_STATUS_OK, NULL);
    require("touchdown as in the hysteresis", td.power_mw == h.touchdown.power_mw);
    opts.contact_threshold_un = 0.0;
    expect("zero threshold", hdi_model_touchdown(model, &opts, &td), HDI_STATUS_INVALID_INPUT,
           "options.contact_threshold_un");
    HdiPullIn pi;
    expect("pull-in", hdi_model_pull_in(model, NULL, 0.0, &pi), HDI_STATUS_OK, NULL);
    require("pull-in voltage positive", pi.voltage_v > 0.0);
    expect("model free", hdi_model_free(model), HDI_STATUS_OK, NULL);
    expect("model freed", hdi_model_touchdown(model, NULL, &td), HDI_STATUS_INVALID_HANDLE,
           "model");

    if (failures != 0) {
        printf("misuse: %d checks failed\n", failures);
        return 1;
    }
    printf("misuse: all checks passed\n");
    return 0;
}
