/*
 * scenario_many.h — many-particle scenarios (docs/many.md, "From the command line"): the
 * resolved set-up that cli/scenario_many.c builds from [box], [walls], [insert],
 * [insert.NAME], [particle.NAME], [run] and [dump] plus the shared [fluid], [material.NAME],
 * [models], [model.NAME], [integrator] and [sim] sections, and that cli/run_many.c runs.
 *
 * Error convention as scenario.h: a rejected input prints "FILE:LINE: ..." and gives
 * CLI_EXIT_USAGE (2) before anything is written.
 */
#ifndef WETDEM_CLI_SCENARIO_MANY_H
#define WETDEM_CLI_SCENARIO_MANY_H

#include "scenario.h"

/* Most materials a many-particle scenario may name. */
#define CLI_MANY_MAX_MATERIALS 32

/* Everything a many-particle run needs, resolved from a scenario. */
struct cli_many_setup {
    struct wetdem_sim* sim; /* owned: materials, fluid, models, walls, particles */
    char material_names[CLI_MANY_MAX_MATERIALS][CLI_NAME_MAX]; /* of sim's materials 0, 1, ... */
    struct wetdem_many_settings many; /* periodic box, dt, skin, energy budget; no outputs */
    double box[3];                    /* box edges [m]: the box is [0, box[k]] */
    unsigned long long steps;         /* from [run] steps, or 0 when t_end is given */
    double t_end;                     /* [run] t_end [s], or 0 when steps is given */
    bool vtk_every_given, csv_every_given;
    unsigned long long vtk_every;        /* steps between VTK frames (0: none) */
    unsigned long long csv_every;        /* steps between CSV rows (0: none) */
    unsigned long long checkpoint_every; /* steps between checkpoints (0: stop and end only) */
    bool vtk_binary;
    bool vtk_links;                      /* also PREFIX_links_NNNNNN.vtk with each frame */
    char vtk_prefix[CLI_VALUE_MAX];      /* "" = no VTK files */
    char csv_name[CLI_VALUE_MAX];        /* ends in ".csv"; "" = none */
    char checkpoint_name[CLI_VALUE_MAX]; /* "" = none */
    char summary_name[CLI_VALUE_MAX];    /* "" = none */
};

/* Builds the simulation of a many-particle scenario (every input check, including the
 * insertion). Returns CLI_EXIT_OK, CLI_EXIT_USAGE (message printed, nothing allocated) or
 * CLI_EXIT_RUNTIME (out of memory). */
int cli_many_build(const struct cli_scenario* sc, struct cli_many_setup* su);
/* Frees the simulation of a setup. */
void cli_many_setup_free(struct cli_many_setup* su);
/* Reports a library message about the run set-up at [box] (periodic box, cell list) or
 * [run] (time step, reach) with the scenario's file and line, and returns CLI_EXIT_USAGE;
 * when the library's status is WETDEM_ERR_NOMEM, with the file only, CLI_EXIT_RUNTIME. */
int cli_many_report_start(const struct cli_scenario* sc, int status, const char* msg);

#endif
