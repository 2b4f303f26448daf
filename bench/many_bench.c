/*
 * many_bench.c — the many-particle benchmark system of bench/20-many.sh, run in wetdem, and
 * the same initial state written as a LIGGGHTS data file (the decks in bench/liggghts read it).
 *
 * System: n polydisperse spheres (R uniform in [0.9, 1.0] mm, 2500 kg/m^3, E = 10 MPa,
 * nu = 0.3, e = 0.5, mu = 0.5) on a 20 x 20 x (n/400) lattice of spacing 2.05 mm with Gaussian
 * velocities (sigma 0.1 m/s, seed 1), settling in a closed box under gravity.
 *   dry: hertz + mindlin;  wet: hertz + mindlin + sb (thin-film viscous, 20 um films,
 *   mu_f = 0.01 Pa s) + capillary (sigma = 0.02 N/m). bench/bridge_floor.c, the floor of the
 *   wet cost, repeats these film, viscosity and tension values: change them together.
 *   --film changes the wet spheres' film thickness (bench/20-many.sh's film sweep: the wet cost
 *   against the number of pairs within the films); a thin film on a sphere of radius R holds
 *   3 delta / R of its volume in liquid, so 20 um on R ~ 0.95 mm is about 6 %, and 3.2 um 1 %,
 *   the liquid content of the LIGGGHTS deck.
 * dt = 1e-5 s (as the LIGGGHTS decks; --dt changes it, e.g. 1e-9 s for the frozen-configuration
 * protocol of bench/20-many.sh). The first `settle` steps are not timed.
 *
 * Same-state protocol (the like-for-like wet/dry comparison of bench/20-many.sh): --state-out
 * writes the state at the end of the run (positions, radii, velocities, spins) as a LIGGGHTS
 * data file; --state-in starts from such a file instead of the lattice (the box is the same),
 * so wetdem dry, wetdem wet and both LIGGGHTS variants run the same configuration. Contact
 * histories are not carried over, in either code.
 *
 * Cross-check with LIGGGHTS (scripts/validate.d/47-liggghts.sh): --frictionless leaves hertz
 * alone (no mindlin) and --restitution E sets e (1: elastic, where the force depends on the
 * positions only and both codes' velocity Verlet steps are the same map); --trace FILE writes
 * the state every --trace-every K steps from the start, as LIGGGHTS' dump of
 * bench/liggghts/frictionless.in does;
 * --perturb moves every sphere by one unit in the last place of its x, the reference for how
 * fast rounding differences grow in this system.
 *
 * Usage: many_bench [--wet] [--film M] [--n N] [--settle S] [--steps S] [--dt DT] [--data FILE]
 *                   [--budget] [--state-in FILE] [--state-out FILE]
 *                   [--frictionless] [--restitution E] [--trace FILE] [--trace-every K]
 *                   [--perturb]
 * Prints one line: "wetdem <dry|wet> n=.. threads=.. steps=.. seconds=.. cpu_seconds=..
 * psteps_per_s=..
 * maxrss_kb=.. contacts=.. bridges=.. pairs=.. builds=.. kick_s=.. forces_s=.. lists_s=.. film=.."
 * (kick_s, forces_s, lists_s: the timed steps' wall time in kicks and drifts, force passes and
 * list builds, wetdem_many_stats; film: the wet spheres' film thickness, 0 dry). Uses only the
 * public API.
 */
#include <math.h>
#include <omp.h>
#include <sys/resource.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "wetdem.h"

#define SPACING 2.05e-3
#define GAP 0.05e-3

static long max_rss_kb(void)
{
    FILE* f = fopen("/proc/self/status", "r");
    char line[256];
    long kb = -1;
    while (f && fgets(line, sizeof line, f))
        if (sscanf(line, "VmHWM: %ld", &kb) == 1)
            break;
    if (f)
        fclose(f);
    return kb;
}

/* User + system CPU time of this process [s]. */
static double cpu_seconds(void)
{
    struct rusage u;
    getrusage(RUSAGE_SELF, &u);
    return (double)u.ru_utime.tv_sec + 1e-6 * (double)u.ru_utime.tv_usec +
           (double)u.ru_stime.tv_sec + 1e-6 * (double)u.ru_stime.tv_usec;
}

static void die(struct wetdem_sim* sim, int st, const char* what)
{
    fprintf(stderr, "many_bench: %s failed (%s): %s\n", what, wetdem_status_name(st),
            sim ? wetdem_sim_errmsg(sim) : "");
    exit(1);
}

static void write_data(const char* path, struct wetdem_sim* sim, const double hi[3])
{
    size_t n;
    const struct wetdem_particle* p = wetdem_sim_particles_const(sim, &n);
    FILE* f = fopen(path, "w");
    if (!f) {
        fprintf(stderr, "many_bench: cannot write %s\n", path);
        exit(1);
    }
    fprintf(f,
            "wetdem benchmark system (bench/many_bench.c)\n\n%zu atoms\n1 atom types\n\n"
            "0 %.17g xlo xhi\n0 %.17g ylo yhi\n0 %.17g zlo zhi\n\nAtoms\n\n",
            n, hi[0], hi[1], hi[2]);
    for (size_t k = 0; k < n; k++)
        fprintf(f, "%zu 1 %.17g 2500 %.17g %.17g %.17g\n", k + 1, 2 * p[k].radius, p[k].pos.x,
                p[k].pos.y, p[k].pos.z);
    fputs("\nVelocities\n\n", f);
    for (size_t k = 0; k < n; k++)
        fprintf(f, "%zu %.17g %.17g %.17g %.17g %.17g %.17g\n", k + 1, p[k].vel.x, p[k].vel.y,
                p[k].vel.z, p[k].omega.x, p[k].omega.y, p[k].omega.z);
    fclose(f);
}

/* Number of atoms in a data file written by write_data (0 if unreadable). */
static size_t data_atoms(const char* path)
{
    FILE* f = fopen(path, "r");
    char line[512];
    size_t n = 0;
    while (f && fgets(line, sizeof line, f))
        if (sscanf(line, "%zu atoms", &n) == 1)
            break;
    if (f)
        fclose(f);
    return n;
}

/* Replaces the particles of sim by those of a data file written by write_data. */
static void read_data(const char* path, struct wetdem_sim* sim)
{
    FILE* f = fopen(path, "r");
    if (!f) {
        fprintf(stderr, "many_bench: cannot read %s\n", path);
        exit(1);
    }
    size_t n;
    struct wetdem_particle* p = wetdem_sim_particles(sim, &n);
    char line[512];
    int section = 0; /* 1 atoms, 2 velocities */
    size_t seen = 0;
    while (fgets(line, sizeof line, f)) {
        size_t id;
        double a[7];
        if (!strncmp(line, "Atoms", 5))
            section = 1;
        else if (!strncmp(line, "Velocities", 10))
            section = 2;
        else if (section == 1 &&
                 sscanf(line, "%zu %*d %lf %lf %lf %lf %lf", &id, &a[0], &a[1], &a[2], &a[3],
                        &a[4]) == 6 &&
                 id >= 1 && id <= n) {
            p[id - 1].radius = 0.5 * a[0];
            p[id - 1].mass = a[1] * 4.0 / 3.0 * 3.14159265358979323846 * p[id - 1].radius *
                             p[id - 1].radius * p[id - 1].radius;
            p[id - 1].pos = (struct wetdem_vec3){a[2], a[3], a[4]};
            seen++;
        } else if (section == 2 &&
                   sscanf(line, "%zu %lf %lf %lf %lf %lf %lf", &id, &a[0], &a[1], &a[2], &a[3],
                          &a[4], &a[5]) == 7 &&
                   id >= 1 && id <= n) {
            p[id - 1].vel = (struct wetdem_vec3){a[0], a[1], a[2]};
            p[id - 1].omega = (struct wetdem_vec3){a[3], a[4], a[5]};
        }
    }
    fclose(f);
    if (seen != n) {
        fprintf(stderr, "many_bench: %s holds %zu of %zu atoms\n", path, seen, n);
        exit(1);
    }
}

/* Appends the state at step `step` to the trace: "step id x y z vx vy vz" a sphere. */
static void write_trace(FILE* f, struct wetdem_sim* sim, unsigned long step)
{
    size_t n;
    const struct wetdem_particle* p = wetdem_sim_particles_const(sim, &n);
    for (size_t k = 0; k < n; k++)
        fprintf(f, "%lu %zu %.17g %.17g %.17g %.17g %.17g %.17g\n", step, k + 1, p[k].pos.x,
                p[k].pos.y, p[k].pos.z, p[k].vel.x, p[k].vel.y, p[k].vel.z);
}

static void setup(struct wetdem_sim* sim, bool wet, bool frictionless, double restitution,
                  double film, size_t n, double hi[3])
{
    struct wetdem_material m = {.density = 2500,
                                .youngs_modulus = 1e7,
                                .poisson_ratio = 0.3,
                                .restitution = restitution,
                                .friction_dry = 0.5,
                                .friction_lub = 0.5,
                                .roughness = 0,
                                .film = wet ? film : 0};
    int st = wetdem_sim_add_material(sim, &m);
    if (st < 0)
        die(sim, st, "material");
    struct wetdem_fluid fl = {.viscosity = 0.01, .surface_tension = 0.02, .density = 1000};
    if ((st = wetdem_sim_set_fluid(sim, &fl)) != WETDEM_OK)
        die(sim, st, "fluid");
    const char* models[] = {"hertz", frictionless ? NULL : "mindlin", wet ? "sb" : NULL,
                            wet ? "capillary" : NULL};
    for (int k = 0; k < 4 && models[k]; k++)
        if ((st = wetdem_sim_enable_model(sim, models[k])) != WETDEM_OK)
            die(sim, st, models[k]);
    size_t layers = (n + 399) / 400;
    hi[0] = hi[1] = 20 * SPACING + 2 * GAP;
    hi[2] = 1.3 * layers * SPACING + 2 * GAP;
    struct wetdem_insert_spec spec = {.layout = WETDEM_INSERT_LATTICE,
                                      .n = n,
                                      .lo = {0, 0, 0},
                                      .hi = {hi[0], hi[1], hi[2]},
                                      .radius_min = 0.9e-3,
                                      .radius_max = 1.0e-3,
                                      .gap = GAP,
                                      .velocity_sigma = 0.1,
                                      .seed = 1};
    if ((st = wetdem_sim_insert(sim, &spec)) != WETDEM_OK)
        die(sim, st, "insert");
    struct wetdem_vec3 normals[6] = {{1, 0, 0},  {-1, 0, 0}, {0, 1, 0},
                                     {0, -1, 0}, {0, 0, 1},  {0, 0, -1}};
    for (int w = 0; w < 6; w++) {
        struct wetdem_vec3 point = {w == 1 ? hi[0] : 0, w == 3 ? hi[1] : 0, w == 5 ? hi[2] : 0};
        if ((st = wetdem_sim_add_wall(sim, point, normals[w], 0)) != WETDEM_OK)
            die(sim, st, "wall");
    }
    wetdem_sim_set_param(sim, "sim.gravity_z", -9.81);
    /* the damping coefficient of LIGGGHTS model hertz (Tsuji form), for the same physics */
    if ((st = wetdem_sim_set_param_str(sim, "hertz.damping", "tsuji")) != WETDEM_OK)
        die(sim, st, "hertz.damping");
}

int main(int argc, char** argv)
{
    bool wet = false, budget = false, frictionless = false, perturb = false;
    double restitution = 0.5;
    const char* trace = NULL;
    unsigned long trace_every = 100;
    size_t n = 20000;
    unsigned long settle = 1000, steps = 2000;
    const char* data = NULL;
    const char* state_in = NULL;
    const char* state_out = NULL;
    double dt = 1e-5, film = 20e-6; /* film: the wet spheres' film thickness [m] */
    for (int k = 1; k < argc; k++) {
        if (!strcmp(argv[k], "--wet"))
            wet = true;
        else if (!strcmp(argv[k], "--budget"))
            budget = true;
        else if (!strcmp(argv[k], "--frictionless"))
            frictionless = true;
        else if (!strcmp(argv[k], "--restitution") && k + 1 < argc &&
                 (restitution = strtod(argv[++k], NULL)) > 0 && restitution <= 1)
            continue;
        else if (!strcmp(argv[k], "--perturb"))
            perturb = true;
        else if (!strcmp(argv[k], "--trace") && k + 1 < argc)
            trace = argv[++k];
        else if (!strcmp(argv[k], "--trace-every") && k + 1 < argc &&
                 (trace_every = strtoul(argv[++k], NULL, 10)) > 0)
            continue;
        else if (!strcmp(argv[k], "--n") && k + 1 < argc)
            n = strtoul(argv[++k], NULL, 10);
        else if (!strcmp(argv[k], "--settle") && k + 1 < argc)
            settle = strtoul(argv[++k], NULL, 10);
        else if (!strcmp(argv[k], "--steps") && k + 1 < argc)
            steps = strtoul(argv[++k], NULL, 10);
        else if (!strcmp(argv[k], "--data") && k + 1 < argc)
            data = argv[++k];
        else if (!strcmp(argv[k], "--state-in") && k + 1 < argc)
            state_in = argv[++k];
        else if (!strcmp(argv[k], "--state-out") && k + 1 < argc)
            state_out = argv[++k];
        else if (!strcmp(argv[k], "--dt") && k + 1 < argc && (dt = strtod(argv[++k], NULL)) > 0)
            continue;
        else if (!strcmp(argv[k], "--film") && k + 1 < argc &&
                 (film = strtod(argv[++k], NULL)) > 0 && film < 1e-3)
            continue;
        else {
            fprintf(stderr, "usage: many_bench [--wet] [--film M (0 < M < 1e-3 m)] [--budget] "
                            "[--n N] [--settle S] [--steps S] [--dt DT] [--data FILE] "
                            "[--state-in FILE] [--state-out FILE] [--frictionless] "
                            "[--restitution E (0 < E <= 1)] [--trace FILE] [--trace-every K] "
                            "[--perturb]\n");
            return 2;
        }
    }
    if (state_in && !(n = data_atoms(state_in))) {
        fprintf(stderr, "many_bench: no atoms in %s\n", state_in);
        return 1;
    }
    struct wetdem_sim* sim = wetdem_sim_create();
    double hi[3];
    setup(sim, wet, frictionless, restitution, film, n, hi);
    if (state_in)
        read_data(state_in, sim);
    if (perturb) {
        size_t np;
        struct wetdem_particle* p = wetdem_sim_particles(sim, &np);
        for (size_t k = 0; k < np; k++)
            p[k].pos.x = nextafter(p[k].pos.x, INFINITY);
    }
    if (data) {
        write_data(data, sim, hi);
        return 0;
    }
    struct wetdem_many_settings ms = {.dt = dt, .skin = 0.2e-3, .energy_budget = budget};
    int st = wetdem_sim_set_many(sim, &ms);
    if (trace) { /* the traced run: steps 0, K, 2K, ... up to settle + steps, untimed */
        FILE* f = fopen(trace, "w");
        if (!f || st != WETDEM_OK) {
            fprintf(stderr, "many_bench: cannot write %s\n", trace);
            return 1;
        }
        for (unsigned long step = 0;; step += trace_every) {
            if (step && (st = wetdem_sim_integrate(sim, (double)step * dt)) != WETDEM_OK)
                die(sim, st, "traced run");
            write_trace(f, sim, step);
            if (step + trace_every > settle + steps)
                break;
        }
        fclose(f);
        wetdem_sim_free(sim);
        return 0;
    }
    if (st != WETDEM_OK || (st = wetdem_sim_integrate(sim, settle * dt)) != WETDEM_OK)
        die(sim, st, "settling run");
    struct wetdem_many_stats s0, s;
    wetdem_sim_many_stats(sim, &s0); /* (the phase times of the settling steps) */
    double t0 = omp_get_wtime(), c0 = cpu_seconds();
    if ((st = wetdem_sim_integrate(sim, (settle + steps) * dt)) != WETDEM_OK)
        die(sim, st, "timed run");
    double secs = omp_get_wtime() - t0, cpu = cpu_seconds() - c0;
    wetdem_sim_many_stats(sim, &s);
    if (state_out)
        write_data(state_out, sim, hi);
    printf("wetdem %s n=%zu threads=%d steps=%lu seconds=%.3f cpu_seconds=%.3f psteps_per_s=%.4g "
           "maxrss_kb=%ld contacts=%zu bridges=%zu pairs=%zu builds=%llu kick_s=%.6f "
           "forces_s=%.6f lists_s=%.6f film=%g\n",
           wet ? "wet" : "dry", n, omp_get_max_threads(), steps, secs, cpu,
           (double)n * (double)steps / secs, max_rss_kb(), s.contacts, s.bridges, s.candidate_pairs,
           s.list_builds, s.seconds_kick - s0.seconds_kick, s.seconds_forces - s0.seconds_forces,
           s.seconds_lists - s0.seconds_lists, wet ? film : 0.0);
    if (budget) {
        struct wetdem_energy_budget b;
        wetdem_sim_energy_budget(sim, &b);
        printf("energy: input %.6g J, kinetic %.6g, potential %.6g, elastic %.6g, dissipated "
               "%.6g, balance error %.3g\n",
               b.input, b.kinetic, b.potential, b.elastic, b.dissipated, b.balance_error);
    }
    wetdem_sim_free(sim);
    return 0;
}
