/*
 * sim_many_io.c — outputs and persistence of the many-particle mode (docs/many.md): VTK files
 * every N steps with a ParaView .vtk.series index, a CSV of global quantities (energies,
 * contacts, liquid bridges, agglomerates found by union-find over bridged pairs), checkpoints
 * and restart, insertion into a simulation, and the global statistics. Prefix: wetdem_sim_.
 *
 * Restart is bit-identical because the checkpoint holds every input of the next step: the
 * particle state, the time grid (t0, dt, step), the per-pair histories keyed by (i, j) and
 * (i, wall), and the forces and torques of the latest evaluation (recomputing them would
 * advance the histories a second time). The neighbour list itself is rebuilt: every pair
 * within its interaction range is in any valid list, and forces are added in (i, j) order, so
 * the result does not depend on when the list was built.
 */
#include <omp.h>
#include <stdio.h>
#include <unistd.h>
#include <stdlib.h>
#include <errno.h>
#include <string.h>

#include "checkpoint.h"
#include "insert.h"
#include "locale_guard.h"
#include "many.h"
#include "output_vtk.h"
#include "vec3.h"

#define CSV_SUFFIX ".csv"
#define SERIES_SUFFIX ".vtk.series"
/* Energy-budget accumulators of a checkpoint: k0, u0, el0, then per model the work on pairs
 * and on walls and the latest pass's part of each (many.h); checkpoints written before the
 * latest-pass terms were kept have only the first three groups. */
#define N_ENERGY (3 + 4 * WETDEM_MAX_MODELS)
#define N_ENERGY_RIGHT_SUM (3 + 2 * WETDEM_MAX_MODELS)

/* The status of a writer or reader that could not switch to the C locale. */
static int no_c_locale(struct wetdem_sim* sim)
{
    return wetdem_sim_fail(sim, WETDEM_ERR_NOMEM,
                           "out of memory for the C locale of the numbers in files");
}

/* ---- contacts, liquid bridges, agglomerates ---- */

static size_t find_root(size_t* parent, size_t k)
{
    while (parent[k] != k) {
        parent[k] = parent[parent[k]]; /* path halving */
        k = parent[k];
    }
    return k;
}

/* Joins the clusters of particles a and b (union by size; the smaller root under the larger,
 * the lower index first on a tie). */
static void unite(size_t* parent, size_t* size, size_t a, size_t b)
{
    a = find_root(parent, a);
    b = find_root(parent, b);
    if (a == b)
        return;
    if (size[a] < size[b] || (size[a] == size[b] && b < a)) {
        size_t t = a;
        a = b;
        b = t;
    }
    parent[b] = a;
    size[a] += size[b];
}

/* Labels each particle's agglomerate (of >= 2 particles) 1, 2, ... in the order of the
 * agglomerates' lowest particle index, 0 for a particle in none; label[] is scratch of n. */
static void label_agglomerates(size_t* parent, const size_t* size, size_t n, size_t* label,
                               uint32_t* agglomerate)
{
    uint32_t next = 0;
    for (size_t k = 0; k < n; k++)
        label[k] = 0;
    for (size_t k = 0; k < n; k++) {
        size_t r = find_root(parent, k);
        if (size[r] >= 2 && label[r] == 0)
            label[r] = ++next;
        agglomerate[k] = (uint32_t)label[r];
    }
}

int wetdem_sim_many_links(const struct wetdem_sim* sim, const struct wetdem_many_per_particle* per,
                          struct wetdem_many_stats* s)
{
    const struct wetdem_many* m = sim->many;
    size_t n = sim->n_particles;
    s->contacts = s->bridges = s->agglomerates = 0;
    s->mean_agglomerate = 0;
    size_t* parent = malloc((n ? n : 1) * 3 * sizeof *parent);
    if (!parent)
        return WETDEM_ERR_NOMEM;
    size_t* size = parent + n;
    uint32_t* contacts = per ? per->contacts : NULL;
    uint32_t* bridges = per ? per->bridges : NULL;
    for (size_t k = 0; k < n; k++) {
        parent[k] = k;
        size[k] = 1;
        if (contacts)
            contacts[k] = 0;
        if (bridges)
            bridges[k] = 0;
    }
    /* every pair within a model's range is in the candidate list */
    for (size_t q = 0; q < m->cl.n_pairs; q++) {
        size_t i = m->cl.pairs[q].i, j = m->cl.pairs[q].j;
        struct wetdem_contact c;
        wetdem_sim_many_contact(sim, i, j, false, &c);
        const double* hist = wetdem_many_pair_history(sim, q);
        if (wetdem_sim_contact_is_in_contact(sim, &c, hist)) {
            s->contacts++;
            if (contacts) {
                contacts[i]++;
                contacts[j]++;
            }
        }
        if (wetdem_sim_contact_is_bridged(sim, &c, hist)) {
            s->bridges++;
            if (bridges) {
                bridges[i]++;
                bridges[j]++;
            }
            unite(parent, size, i, j);
        }
    }
    for (size_t i = 0; i < n; i++)
        for (size_t w = 0; w < wetdem_many_walls_of(sim, i); w++) {
            struct wetdem_contact c;
            wetdem_sim_many_contact(sim, i, w, true, &c);
            if (wetdem_sim_contact_is_in_contact(sim, &c, wetdem_many_wall_history(sim, i, w))) {
                s->contacts++;
                if (contacts)
                    contacts[i]++;
            }
        }
    size_t members = 0;
    for (size_t k = 0; k < n; k++)
        if (parent[k] == k && size[k] >= 2) {
            s->agglomerates++;
            members += size[k];
        }
    s->mean_agglomerate = s->agglomerates ? (double)members / (double)s->agglomerates : 0.0;
    if (per && per->agglomerate)
        label_agglomerates(parent, size, n, parent + 2 * n, per->agglomerate);
    free(parent);
    return WETDEM_OK;
}

/* The speeds of the statistics, from the state of the run m (one source for
 * wetdem_sim_many_stats and wetdem_sim_many_speeds). */
static void run_speeds(const struct wetdem_many* m, double* speed_scale, double* speed_bound,
                       double* largest_speed)
{
    *speed_scale = m->speed_scale;
    *speed_bound = m->speed_bound;
    *largest_speed = sqrt(m->v2_seen);
}

/* The fields of the statistics other than the links (counts, step, timers). */
static void fill_run_stats(const struct wetdem_sim* sim, struct wetdem_many_stats* s)
{
    const struct wetdem_many* m = sim->many;
    s->candidate_pairs = m->cl.n_pairs;
    s->list_builds = m->cl.n_builds;
    s->dt = m->dt;
    s->relaxation_time = m->relaxation_time;
    s->contact_time = m->contact_time;
    s->hmin_crossing_time = m->crossing_time;
    run_speeds(m, &s->speed_scale, &s->speed_bound, &s->largest_speed);
    s->step = m->step;
    s->seconds_kick = m->seconds_kick;
    s->seconds_forces = m->seconds_forces;
    s->seconds_lists = m->seconds_lists;
    s->seconds_output = m->seconds_output;
    s->threads = wetdem_many_parallel(m, sim->n_particles) ? omp_get_max_threads() : 1;
}

int wetdem_sim_many_stats(const struct wetdem_sim* sim, struct wetdem_many_stats* s)
{
    memset(s, 0, sizeof *s);
    int st = wetdem_sim_many_check_run(sim, "many_stats");
    if (st == WETDEM_OK)
        st = wetdem_sim_many_check_report(sim, "many_stats");
    if (st != WETDEM_OK)
        return st;
    st = wetdem_sim_many_links(sim, NULL, s);
    if (st != WETDEM_OK)
        return wetdem_sim_fail((struct wetdem_sim*)sim, st,
                               "many_stats: out of memory for the agglomerates of %zu particles",
                               sim->n_particles);
    fill_run_stats(sim, s);
    return WETDEM_OK;
}

int wetdem_sim_many_speeds(const struct wetdem_sim* sim, double* speed_scale, double* speed_bound,
                           double* largest_speed)
{
    int st = wetdem_sim_many_check_run(sim, "many_speeds");
    if (st != WETDEM_OK)
        return st;
    if (!speed_scale || !speed_bound || !largest_speed)
        return wetdem_sim_fail((struct wetdem_sim*)sim, WETDEM_ERR_INVALID,
                               "many_speeds: NULL output");
    run_speeds(sim->many, speed_scale, speed_bound, largest_speed);
    return WETDEM_OK;
}

/* ---- VTK and CSV ---- */

/* Each particle's contacts and liquid bridges as the enabled models define them and the label
 * of its agglomerate, into *v, and the run's links into *s (wetdem_sim_many_links). Returns the
 * block that holds v's arrays, for free(); NULL, with the failure recorded, when out of memory. */
static uint32_t* particle_counts(struct wetdem_sim* sim, struct wetdem_many_stats* s,
                                 struct wetdem_output_vtk_counts* v)
{
    size_t n = sim->n_particles ? sim->n_particles : 1;
    uint32_t* block = malloc(3 * n * sizeof *block);
    struct wetdem_many_per_particle per = {0};
    if (block) /* (no offset from NULL when out of memory) */
        per = (struct wetdem_many_per_particle){block, block + n, block + 2 * n};
    if (!block || wetdem_sim_many_links(sim, &per, s) != WETDEM_OK) {
        free(block);
        wetdem_sim_fail(sim, WETDEM_ERR_NOMEM, "out of memory for the contact counts");
        return NULL;
    }
    *v = (struct wetdem_output_vtk_counts){per.contacts, per.bridges, per.agglomerate};
    return block;
}

/* The frame at `path`, with each particle's counts (NULL: none, a run not started). */
static int write_particle_frame(struct wetdem_sim* sim, const char* path, bool binary,
                                const struct wetdem_output_vtk_counts* counts)
{
    char msg[512];
    int st = wetdem_output_vtk_write(path, sim->particles, sim->n_particles, counts,
                                     sim->engine.time, binary, msg, sizeof msg);
    return st == WETDEM_OK ? st : wetdem_sim_fail(sim, st, "%s", msg);
}

static int write_vtk(struct wetdem_sim* sim, const char* path, bool binary)
{
    if (!path)
        return wetdem_sim_fail(sim, WETDEM_ERR_INVALID, "write_vtk: NULL path");
    uint32_t* block = NULL;
    struct wetdem_output_vtk_counts counts;
    if (sim->many && sim->many->started) {
        struct wetdem_many_stats s;
        if (!(block = particle_counts(sim, &s, &counts)))
            return WETDEM_ERR_NOMEM;
    }
    int st = write_particle_frame(sim, path, binary, block ? &counts : NULL);
    free(block);
    return st;
}

/* ---- links: contacts, liquid bridges and pairs apart that a model acts on, as lines ---- */

/* Link of contact c (history `hist`, committed) into *l when it is a contact or a bridge, or
 * a model exerts a force on it (lubrication between spheres apart: nijssen, reynolds); false
 * otherwise. The force is that of the enabled models at this state with the history as the
 * latest step left it, not advanced (dt = 0, on a copy). */
static bool link_of(const struct wetdem_sim* sim, struct wetdem_contact* c, const double* hist,
                    struct wetdem_output_vtk_link* l, int* status)
{
    bool contact = wetdem_sim_contact_is_in_contact(sim, c, hist);
    bool bridge = wetdem_sim_contact_is_bridged(sim, c, hist); /* (to a wall too, here) */
    double scratch[WETDEM_HISTORY_SCRATCH];
    if (sim->history_len)
        memcpy(scratch, hist, sim->history_len * sizeof *scratch);
    c->dt = 0.0;
    struct wetdem_pair_force f;
    int st = wetdem_sim_eval_contact(sim, c, sim->history_len ? scratch : NULL, &f, NULL);
    if (st < 0 && *status == WETDEM_OK)
        *status = st;
    if (!contact && !bridge && (st < 0 || (f.f_normal == 0 && vec3_norm(f.f_tan) == 0)))
        return false;
    const struct wetdem_vec3 a = sim->particles[c->i].pos;
    double reach = c->gap + c->radius_i + (c->is_wall ? 0.0 : c->radius_j); /* a to b */
    *l = (struct wetdem_output_vtk_link){
        .a = a,
        .b = vec3_axpy(a, -reach, c->normal), /* the normal points from j to i */
        .i = (int32_t)c->i,
        .j = c->is_wall ? -1 - (int32_t)c->j : (int32_t)c->j,
        .contact = contact,
        .bridge = bridge,
        .gap = c->gap,
        .f_normal = st < 0 ? NAN : f.f_normal,
        .f_tangential = st < 0 ? NAN : vec3_norm(f.f_tan),
        .force = st < 0 ? vec3(NAN, NAN, NAN) : vec3_axpy(f.f_tan, f.f_normal, c->normal),
    };
    return true;
}

/* Appends link l to the growing array *links (count *n, capacity *cap). */
static bool push_link(struct wetdem_output_vtk_link** links, size_t* n, size_t* cap,
                      const struct wetdem_output_vtk_link* l)
{
    if (*n == *cap) {
        size_t c = *cap ? 2 * *cap : 1024;
        struct wetdem_output_vtk_link* grown = realloc(*links, c * sizeof *grown);
        if (!grown)
            return false;
        *links = grown;
        *cap = c;
    }
    (*links)[(*n)++] = *l;
    return true;
}

static int write_vtk_links(struct wetdem_sim* sim, const char* path, bool binary)
{
    if (!path)
        return wetdem_sim_fail(sim, WETDEM_ERR_INVALID, "links: NULL path");
    const struct wetdem_many* m = sim->many;
    if (!m || !m->started)
        return wetdem_sim_fail(sim, WETDEM_ERR_INVALID,
                               "links: a VTK file of links needs a started many-particle run");
    if (sim->history_len > WETDEM_HISTORY_SCRATCH)
        return wetdem_sim_fail(sim, WETDEM_ERR_INVALID,
                               "links: the models keep %zu history values a pair, more than %d",
                               sim->history_len, WETDEM_HISTORY_SCRATCH);
    struct wetdem_output_vtk_link* links = NULL;
    size_t n = 0, cap = 0;
    bool ok = true;
    int status = WETDEM_OK;
    for (size_t q = 0; ok && q < m->cl.n_pairs; q++) { /* every pair within range is listed */
        struct wetdem_contact c;
        struct wetdem_output_vtk_link l;
        wetdem_sim_many_contact(sim, m->cl.pairs[q].i, m->cl.pairs[q].j, false, &c);
        if (link_of(sim, &c, wetdem_many_pair_history(sim, q), &l, &status))
            ok = push_link(&links, &n, &cap, &l);
    }
    for (size_t i = 0; ok && i < sim->n_particles; i++)
        for (size_t w = 0; ok && w < wetdem_many_walls_of(sim, i); w++) {
            struct wetdem_contact c;
            struct wetdem_output_vtk_link l;
            wetdem_sim_many_contact(sim, i, w, true, &c);
            if (link_of(sim, &c, wetdem_many_wall_history(sim, i, w), &l, &status))
                ok = push_link(&links, &n, &cap, &l);
        }
    int st = WETDEM_OK;
    char msg[512];
    if (!ok)
        st = wetdem_sim_fail(sim, WETDEM_ERR_NOMEM, "out of memory for the links");
    else if (status != WETDEM_OK)
        st = wetdem_sim_fail(sim, status, "links: a model failed on a link's force");
    else if ((st = wetdem_output_vtk_links_write(path, links, n, sim->engine.time, binary, msg,
                                                 sizeof msg)) != WETDEM_OK)
        st = wetdem_sim_fail(sim, st, "%s", msg);
    free(links);
    return st;
}

/* "<prefix><suffix>" into buf. */
static int prefixed(struct wetdem_sim* sim, char* buf, size_t n, const char* suffix)
{
    if ((size_t)snprintf(buf, n, "%s%s", sim->many->output_prefix, suffix) >= n)
        return wetdem_sim_fail(sim, WETDEM_ERR_IO, "output prefix too long");
    return WETDEM_OK;
}

/* File name without its directory, for the series index (relative to the series file). */
static const char* base_name(const char* path)
{
    const char* s = strrchr(path, '/');
    return s ? s + 1 : path;
}

/* Appends an entry to the series index (names and times). */
static int add_series_entry(struct wetdem_sim* sim, const char* name, double time)
{
    struct wetdem_many* m = sim->many;
    size_t cap = m->vtk_names_cap;
    if (m->n_series + 1 > cap) {
        cap = cap ? 2 * cap : 64;
        char** names = realloc(m->vtk_names, cap * sizeof *names);
        if (names)
            m->vtk_names = names;
        double* times = realloc(m->vtk_times, cap * sizeof *times);
        if (times)
            m->vtk_times = times;
        if (!names || !times)
            return wetdem_sim_fail(sim, WETDEM_ERR_NOMEM, "out of memory");
        m->vtk_names_cap = cap;
    }
    size_t k = m->n_series;
    m->vtk_names[k] = malloc(strlen(name) + 1);
    if (!m->vtk_names[k])
        return wetdem_sim_fail(sim, WETDEM_ERR_NOMEM, "out of memory");
    strcpy(m->vtk_names[k], name);
    m->vtk_times[k] = time;
    m->n_series++;
    return WETDEM_OK;
}

/* The name of the links of series entry `name` (X_NNNNNN.vtk: X_links_NNNNNN.vtk), malloc'd. */
static char* links_name(const char* name)
{
    const char* digits = strrchr(name, '_');
    size_t head = digits ? (size_t)(digits - name) : strlen(name);
    char* s = malloc(strlen(name) + sizeof WETDEM_LINKS_SUFFIX);
    if (s)
        sprintf(s, "%.*s" WETDEM_LINKS_SUFFIX "%s", (int)head, name, name + head);
    return s;
}

/* The index <prefix>_links.vtk.series: the links of the series entries from links_from on. */
static int write_links_series(struct wetdem_sim* sim)
{
    struct wetdem_many* m = sim->many;
    size_t n = m->n_series - m->links_from;
    char** names = calloc(n ? n : 1, sizeof *names);
    int st = names ? WETDEM_OK : WETDEM_ERR_NOMEM;
    for (size_t k = 0; st == WETDEM_OK && k < n; k++)
        if (!(names[k] = links_name(m->vtk_names[m->links_from + k])))
            st = WETDEM_ERR_NOMEM;
    if (st != WETDEM_OK)
        st = wetdem_sim_fail(sim, st, "out of memory for the links' index");
    char series[4096], msg[512];
    if (st == WETDEM_OK)
        st = prefixed(sim, series, sizeof series, WETDEM_LINKS_SUFFIX SERIES_SUFFIX);
    if (st == WETDEM_OK && wetdem_output_vtk_series_write(series, (const char* const*)names,
                                                          m->vtk_times + m->links_from, n, msg,
                                                          sizeof msg) != WETDEM_OK)
        st = wetdem_sim_fail(sim, WETDEM_ERR_IO, "%s", msg);
    for (size_t k = 0; names && k < n; k++)
        free(names[k]);
    free(names);
    return st;
}

/* The next frame of the series, with each particle's counts, and with vtk_links its links. */
static int write_vtk_frame(struct wetdem_sim* sim, const struct wetdem_output_vtk_counts* counts)
{
    struct wetdem_many* m = sim->many;
    char path[4096], series[4096], links_prefix[4096], links[4200];
    wetdem_output_vtk_path(path, sizeof path, m->output_prefix, m->vtk_files);
    int st = write_particle_frame(sim, path, m->set.vtk_binary, counts);
    if (st == WETDEM_OK && m->set.vtk_links &&
        (st = prefixed(sim, links_prefix, sizeof links_prefix, WETDEM_LINKS_SUFFIX)) == WETDEM_OK) {
        wetdem_output_vtk_path(links, sizeof links, links_prefix, m->vtk_files);
        st = write_vtk_links(sim, links, m->set.vtk_binary);
    }
    if (st == WETDEM_OK)
        st = add_series_entry(sim, base_name(path), sim->engine.time);
    if (st != WETDEM_OK)
        return st;
    m->vtk_files++;
    st = prefixed(sim, series, sizeof series, SERIES_SUFFIX);
    char msg[512];
    if (st == WETDEM_OK &&
        wetdem_output_vtk_series_write(series, (const char* const*)m->vtk_names, m->vtk_times,
                                       m->n_series, msg, sizeof msg) != WETDEM_OK)
        st = wetdem_sim_fail(sim, WETDEM_ERR_IO, "%s", msg);
    if (st == WETDEM_OK && m->set.vtk_links)
        st = write_links_series(sim);
    return st;
}

/* With vtk_links after a restart: the first series entry from which on every entry has its
 * links file (the directory of the series is that of the prefix). Returns WETDEM_OK or
 * WETDEM_ERR_NOMEM. */
static int find_links_from(struct wetdem_sim* sim)
{
    struct wetdem_many* m = sim->many;
    const char* slash = strrchr(m->output_prefix, '/');
    int dir = slash ? (int)(slash - m->output_prefix + 1) : 0;
    for (m->links_from = m->n_series; m->links_from > 0; m->links_from--) {
        char* name = links_name(m->vtk_names[m->links_from - 1]);
        if (!name)
            return wetdem_sim_fail(sim, WETDEM_ERR_NOMEM, "out of memory for the links' index");
        char path[4096];
        snprintf(path, sizeof path, "%.*s%s", dir, m->output_prefix, name);
        bool there = access(path, F_OK) == 0;
        free(name);
        if (!there)
            break;
    }
    return WETDEM_OK;
}

/* After a restart: the frames 0 .. vtk_files-1 written before it go back into the series
 * index, with the times the existing .vtk.series file gives them (frames it does not list are
 * left out of the index; their files are not overwritten, numbering continues). */
static int reload_series(struct wetdem_sim* sim)
{
    struct wetdem_many* m = sim->many;
    char series[4096], line[8192];
    if (!m->output_prefix || prefixed(sim, series, sizeof series, SERIES_SUFFIX) != WETDEM_OK)
        return WETDEM_OK;
    FILE* f = fopen(series, "r");
    for (uint64_t k = 0; f && k < m->vtk_files && fgets(line, sizeof line, f);) {
        char path[4096];
        double t;
        const char* at = strstr(line, "\"time\" : ");
        if (!at || sscanf(at, "\"time\" : %lf", &t) != 1)
            continue;
        wetdem_output_vtk_path(path, sizeof path, m->output_prefix, k);
        char quoted[4200];
        snprintf(quoted, sizeof quoted, "\"%s\"", base_name(path));
        if (strstr(line, quoted)) {
            int st = add_series_entry(sim, base_name(path), t);
            if (st != WETDEM_OK) {
                fclose(f);
                return st;
            }
        }
        k++;
    }
    if (f)
        fclose(f);
    return m->set.vtk_links ? find_links_from(sim) : WETDEM_OK;
}

/* The CSV's '#' lines, its provenance (csv_comment, else the version) and what it holds, then
 * its columns, "name [unit]" as every CSV of wetdem's CLI (docs/concepts.md). */
static void csv_header(const struct wetdem_sim* sim, FILE* f)
{
    const char* comment = sim->many->set.csv_comment;
    if (!comment || !*comment)
        fprintf(f, "# wetdem %s\n", WETDEM_VERSION);
    for (const char* line = comment; line && *line;) {
        size_t n = strcspn(line, "\n");
        fprintf(f, "# %.*s\n", (int)n, line);
        line += n + (line[n] == '\n');
    }
    fputs("# many-particle run: global quantities\n" WETDEM_MANY_CSV_HEAD
          "kinetic [J],potential [J],elastic [J],contacts [count],bridges [count],"
          "agglomerates [count],mean_agglomerate_size [-],candidate_pairs [count]",
          f);
    for (size_t k = 0; sim->many->set.energy_budget && k < sim->n_models; k++)
        fprintf(f, ",work_%s [J]", sim->models[k].model->name);
    if (sim->many->set.energy_budget)
        fputs(",dissipated [J],balance_error [J]", f);
    fputc('\n', f);
}

/* v, or 0 for -0, so that a zero reads "0", never "-0" (a potential of no height, -m g.0);
 * every other value bit for bit. */
static double plain_zero(double v)
{
    return v == 0.0 ? 0.0 : v;
}

/* The next row of the CSV; `links`, when not NULL, holds the run's links at this step (worked
 * out for the VTK frame of the same step), else they are worked out here. */
static int write_csv_row(struct wetdem_sim* sim, const struct wetdem_many_stats* links)
{
    struct wetdem_many* m = sim->many;
    char path[4096];
    int st = prefixed(sim, path, sizeof path, CSV_SUFFIX);
    FILE* f = st == WETDEM_OK ? fopen(path, m->csv_rows ? "a" : "w") : NULL;
    if (!f)
        return st != WETDEM_OK ? st
                               : wetdem_sim_fail(sim, WETDEM_ERR_IO, "cannot open '%s': %s", path,
                                                 strerror(errno));
    /* a header for a new file, also when a resumed run's CSV is missing or empty */
    if (m->csv_rows == 0 || (fseek(f, 0, SEEK_END) == 0 && ftell(f) == 0))
        csv_header(sim, f);
    struct wetdem_many_stats s;
    if (links) {
        s = *links;
        fill_run_stats(sim, &s);
    } else
        st = wetdem_sim_many_stats(sim, &s);
    if (st != WETDEM_OK) {
        fclose(f);
        return wetdem_sim_fail(sim, st, "out of memory for the contact counts");
    }
    /* the energies once: the budget has them (each pass over the pairs asks every model) */
    struct wetdem_energy_budget b;
    bool budget = m->set.energy_budget && wetdem_sim_energy_budget(sim, &b) == WETDEM_OK;
    if (!budget)
        wetdem_sim_many_energies(sim, &b.kinetic, &b.potential, &b.elastic);
    fprintf(f, "%.9g,%llu,%.9g,%.9g,%.9g,%zu,%zu,%zu,%.6g,%zu", plain_zero(sim->engine.time),
            (unsigned long long)m->step, plain_zero(b.kinetic), plain_zero(b.potential),
            plain_zero(b.elastic), s.contacts, s.bridges, s.agglomerates,
            plain_zero(s.mean_agglomerate), s.candidate_pairs);
    if (budget) {
        for (size_t q = 0; q < sim->n_models && q < WETDEM_ENERGY_MAX_MODELS; q++)
            fprintf(f, ",%.9g", plain_zero(b.work_pair[q] + b.work_wall[q]));
        fprintf(f, ",%.9g,%.3g", plain_zero(b.dissipated), plain_zero(b.balance_error));
    }
    fputc('\n', f);
    errno = 0;
    bool ok = !ferror(f);
    ok = fclose(f) == 0 && ok;
    int err = errno ? errno : EIO; /* (a write's own errno may be gone; fclose's flush fails
                                      again with the reason) */
    m->csv_rows++;
    return ok ? WETDEM_OK
              : wetdem_sim_fail(sim, WETDEM_ERR_IO, "cannot write '%s': %s", path, strerror(err));
}

int wetdem_sim_many_write_csv_row(struct wetdem_sim* sim)
{
    if (!sim || !sim->many || !sim->many->started || !sim->many->output_prefix)
        return wetdem_sim_fail(sim, WETDEM_ERR_INVALID,
                               "many: a CSV row needs a started many-particle run with outputs");
    int checked = wetdem_sim_many_check_report(sim, "many: a CSV row");
    if (checked != WETDEM_OK)
        return checked;
    struct wetdem_locale_guard g;
    if (wetdem_locale_guard_enter(&g) != WETDEM_OK)
        return no_c_locale(sim);
    int st = write_csv_row(sim, NULL);
    wetdem_locale_guard_leave(&g);
    return st;
}

/* Output k is due at multiples of `every` steps, once per step. */
static bool due(uint64_t step, unsigned long long every, uint64_t* next)
{
    if (!every || step < *next)
        return false;
    *next = (step / every + 1) * every;
    return true;
}

static int write_checkpoint(struct wetdem_sim* sim, const char* path);

int wetdem_sim_many_outputs(struct wetdem_sim* sim, bool final)
{
    struct wetdem_many* m = sim->many;
    int st = WETDEM_OK;
    (void) final;
    bool vtk = m->output_prefix && due(m->step, m->set.vtk_every, &m->next_vtk_step);
    bool csv = m->output_prefix && due(m->step, m->set.csv_every, &m->next_csv_step);
    bool ck = m->checkpoint_path && m->step > 0 &&
              due(m->step, m->set.checkpoint_every, &m->next_checkpoint_step);
    /* the C locale for the files' numbers only at the steps that write any (the observer and
     * the progress callback, between them, run in the host's locale) */
    if (!(vtk || csv || ck))
        return WETDEM_OK;
    struct wetdem_locale_guard g;
    if (wetdem_locale_guard_enter(&g) != WETDEM_OK)
        return no_c_locale(sim);
    /* the links are worked out once for the frame and, when due at the same step, the row */
    struct wetdem_many_stats links = {0}; /* zeroed, as wetdem_sim_many_stats starts */
    bool have_links = false;
    if (vtk) {
        struct wetdem_output_vtk_counts per;
        uint32_t* block = particle_counts(sim, &links, &per);
        st = block ? write_vtk_frame(sim, &per) : WETDEM_ERR_NOMEM;
        have_links = block != NULL;
        free(block);
    }
    if (st == WETDEM_OK && csv)
        st = write_csv_row(sim, have_links ? &links : NULL);
    if (st == WETDEM_OK && ck)
        st = write_checkpoint(sim, m->checkpoint_path);
    wetdem_locale_guard_leave(&g);
    return st;
}

/* ---- checkpoints ---- */

/* Fingerprint of everything a checkpoint must be restored into unchanged. */
/* The fingerprint of the set-up, with the energy budget on or off as `budget` (a run resumed
 * with the budget from a checkpoint written without it would report the work since the
 * restart against the energies since the start). */
static uint64_t config_hash_with(const struct wetdem_sim* sim, bool budget)
{
    uint64_t h = wetdem_checkpoint_hash(0, "wetdem-many-2", 13);
    h = wetdem_checkpoint_hash(h, sim->materials,
                               (size_t)sim->n_materials * sizeof(*sim->materials));
    h = wetdem_checkpoint_hash(h, &sim->fluid, sizeof sim->fluid);
    h = wetdem_checkpoint_hash(h, &sim->settings, sizeof sim->settings);
    const struct wetdem_model_slot* slots[WETDEM_MAX_MODELS + 1];
    size_t n = 0;
    for (size_t k = 0; k < sim->n_models; k++)
        slots[n++] = &sim->models[k];
    slots[n++] = &sim->minsep;
    for (size_t k = 0; k < n; k++) {
        h = wetdem_checkpoint_hash(h, slots[k]->model->name, strlen(slots[k]->model->name));
        h = wetdem_checkpoint_hash(h, slots[k]->params, slots[k]->model->params_size);
    }
    for (size_t w = 0; w < sim->n_walls; w++) {
        h = wetdem_checkpoint_hash(h, &sim->walls[w].point, sizeof(struct wetdem_vec3));
        h = wetdem_checkpoint_hash(h, &sim->walls[w].normal, sizeof(struct wetdem_vec3));
        h = wetdem_checkpoint_hash(h, &sim->walls[w].material, sizeof(int));
    }
    const struct wetdem_many_settings* s = &sim->many->set;
    double geo[8] = {s->skin,     s->dt,       s->box_lo.x, s->box_lo.y,
                     s->box_lo.z, s->box_hi.x, s->box_hi.y, s->box_hi.z};
    unsigned char per[4] = {s->periodic[0], s->periodic[1], s->periodic[2], budget};
    h = wetdem_checkpoint_hash(h, geo, sizeof geo);
    return wetdem_checkpoint_hash(h, per, sizeof per);
}

static uint64_t config_hash(const struct wetdem_sim* sim)
{
    return config_hash_with(sim, sim->many->set.energy_budget);
}

/* USER blob: dt, t0, then force and torque of every particle. */
static size_t blob_size(size_t n)
{
    return 2 * sizeof(double) + n * 6 * sizeof(double);
}

/* blob_size(n), then each particle's periodic images (3 doubles). */
static size_t blob_size_images(size_t n)
{
    return blob_size(n) + n * 3 * sizeof(double);
}

/* The speeds kept after the images: the start's speed scale and speed bound and the largest
 * |v'|^2 since the start (struct wetdem_many speed_scale, speed_bound, v2_seen). */
#define BLOB_SPEEDS (3 * sizeof(double))

/* The blob as written now: blob_size_images(n), then BLOB_SPEEDS. */
static size_t blob_size_speeds(size_t n)
{
    return blob_size_images(n) + BLOB_SPEEDS;
}

/* Whether a USER blob of `size` bytes for n particles holds their periodic images. */
static bool blob_has_images(size_t size, size_t n)
{
    return size == blob_size_images(n) || size == blob_size_speeds(n);
}

/* Whether a USER blob of `size` bytes fits n particles: blob_size_speeds(n);
 * blob_size_images(n), written before the speeds were kept (a run resumed from it reports the
 * speeds since the resumption, its speed scale and bound those of the restored state);
 * blob_size(n),
 * written before the images were kept (read as no wraps: such a run's budget had the jumps
 * of its wraps, if gravity acted along a periodic axis); or blob_size(n) and a uint32 per
 * particle, each one's count of solid overlaps at the latest pass, which checkpoints held while
 * the force pass counted them. Nothing reads those counts (the reported ones are worked out
 * from the state: wetdem_sim_many_links), so such a checkpoint resumes the same run and its
 * counts are skipped; the three sizes differ for every n > 0, so no layout is taken for
 * another. */
static bool blob_size_fits(size_t size, size_t n)
{
    return size == blob_size_speeds(n) || size == blob_size_images(n) || size == blob_size(n) ||
           size == blob_size(n) + n * sizeof(uint32_t);
}

static int fill_checkpoint(struct wetdem_sim* sim, struct wetdem_checkpoint* ck)
{
    struct wetdem_many* m = sim->many;
    size_t n = sim->n_particles, nw = sim->n_walls, np = m->cl.n_pairs, len = sim->history_len;
    size_t total = np + n * nw;
    ck->pairs = malloc((total ? total : 1) * sizeof *ck->pairs);
    ck->history = malloc((total * len > 0 ? total * len : 1) * sizeof(double));
    ck->walls = malloc((nw ? nw : 1) * sizeof *ck->walls);
    ck->extra = malloc(blob_size_speeds(n));
    ck->energy = malloc(N_ENERGY * sizeof(double));
    if (!ck->pairs || !ck->history || !ck->walls || !ck->extra || !ck->energy)
        return WETDEM_ERR_NOMEM;
    for (size_t q = 0; q < np; q++)
        ck->pairs[q] = (struct wetdem_checkpoint_pair){m->cl.pairs[q].i, m->cl.pairs[q].j, false};
    for (size_t k = 0; k < n * nw; k++)
        ck->pairs[np + k] = (struct wetdem_checkpoint_pair){k / nw, k % nw, true};
    if (len) {
        memcpy(ck->history, m->history, np * len * sizeof(double));
        memcpy(ck->history + np * len, m->wall_history, n * nw * len * sizeof(double));
    }
    for (size_t w = 0; w < nw; w++)
        ck->walls[w] = (struct wetdem_checkpoint_wall){sim->walls[w].point, sim->walls[w].normal,
                                                       sim->walls[w].material};
    unsigned char* b = ck->extra;
    memcpy(b, &m->dt, 8);
    memcpy(b + 8, &m->t0, 8);
    for (size_t k = 0; k < n; k++) {
        double ft[6] = {m->force[k].x,  m->force[k].y,  m->force[k].z,
                        m->torque[k].x, m->torque[k].y, m->torque[k].z};
        memcpy(b + 16 + k * 48, ft, 48);
    }
    if (n)
        memcpy(b + blob_size(n), m->image, n * sizeof *m->image);
    const double speeds[3] = {m->speed_scale, m->speed_bound, m->v2_seen};
    memcpy(b + blob_size_images(n), speeds, BLOB_SPEEDS);
    double* e = ck->energy;
    e[0] = m->energy.k0;
    e[1] = m->energy.u0;
    e[2] = m->energy.el0;
    memcpy(e + 3, m->energy.work_pair, sizeof m->energy.work_pair);
    memcpy(e + 3 + WETDEM_MAX_MODELS, m->energy.work_wall, sizeof m->energy.work_wall);
    memcpy(e + 3 + 2 * WETDEM_MAX_MODELS, m->energy.last_pair, sizeof m->energy.last_pair);
    memcpy(e + 3 + 3 * WETDEM_MAX_MODELS, m->energy.last_wall, sizeof m->energy.last_wall);
    *ck = (struct wetdem_checkpoint){
        .time = sim->engine.time,
        .step = m->step,
        .config_hash = config_hash(sim),
        .particles = sim->particles,
        .n_particles = n,
        .walls = ck->walls,
        .n_walls = nw,
        .pairs = ck->pairs,
        .history = ck->history,
        .n_pairs = total,
        .history_len = len,
        .stats = sim->engine.stats,
        .energy = ck->energy,
        .n_energy = N_ENERGY,
        .extra = ck->extra,
        .extra_size = blob_size_speeds(n),
        .output = {m->vtk_files, m->csv_rows, m->next_vtk_step, m->next_csv_step},
        .note = m->checkpoint_note};
    return WETDEM_OK;
}

static int write_checkpoint(struct wetdem_sim* sim, const char* path)
{
    if (!path)
        return wetdem_sim_fail(sim, WETDEM_ERR_INVALID, "write_checkpoint: NULL path");
    if (!sim->many || !sim->many->started)
        return wetdem_sim_fail(sim, WETDEM_ERR_INVALID,
                               "checkpoints need a started many-particle run (wetdem_sim_set_many "
                               "and wetdem_sim_integrate)");
    struct wetdem_checkpoint ck = {0};
    int st = fill_checkpoint(sim, &ck);
    char msg[512] = "out of memory writing a checkpoint";
    if (st == WETDEM_OK)
        st = wetdem_checkpoint_write(path, &ck, msg, sizeof msg);
    free(ck.pairs);
    free(ck.history);
    free(ck.walls);
    free(ck.extra);
    free(ck.energy);
    return st == WETDEM_OK ? st : wetdem_sim_fail(sim, st, "%s", msg);
}

/* Whether x[0 .. n) are all finite. */
static bool all_finite(const double* x, size_t n)
{
    for (size_t k = 0; k < n; k++)
        if (!isfinite(x[k]))
            return false;
    return true;
}

/* The rest of a checkpoint that a set-up cannot fingerprint: time and step size, the latest
 * forces and torques, the energy accumulators and histories must be finite (and dt > 0), the
 * pair keys must name particles i < j < n in increasing (i, j) order, and the wall keys the
 * (particle, wall) grid in order, as restore_pairs copies their histories by position. The
 * file's CRC already caught damage; this catches a file that is whole but not a state of this
 * run. */
static int check_restorable_values(struct wetdem_sim* sim, const struct wetdem_checkpoint* ck,
                                   const char* path)
{
    size_t n = ck->n_particles, nw = sim->n_walls, np = ck->n_pairs - n * nw;
    double dt_t0[2];
    memcpy(dt_t0, ck->extra, sizeof dt_t0);
    const char* bad = NULL;
    if (!isfinite(ck->time) || !all_finite(dt_t0, 2) || !(dt_t0[0] > 0))
        bad = "a non-finite time or a step dt that is not > 0";
    for (size_t k = 0; !bad && k < n; k++) {
        double ft[6];
        memcpy(ft, ck->extra + 16 + k * 48, sizeof ft);
        if (!all_finite(ft, 6))
            bad = "a non-finite force or torque";
    }
    for (size_t k = 0; !bad && blob_has_images(ck->extra_size, n) && k < n; k++) {
        double im[3];
        memcpy(im, ck->extra + blob_size(n) + k * sizeof im, sizeof im);
        for (int a = 0; a < 3; a++)
            if (!(isfinite(im[a]) && im[a] == floor(im[a])))
                bad = "a periodic image count that is not a whole number";
    }
    double speeds[3] = {0, 0, 0};
    if (ck->extra_size == blob_size_speeds(n))
        memcpy(speeds, ck->extra + blob_size_images(n), BLOB_SPEEDS);
    if (!bad && !(isfinite(speeds[0]) && speeds[0] >= 0 && speeds[1] >= 0 && isfinite(speeds[2]) &&
                  speeds[2] >= 0)) /* (the bound may be infinite) */
        bad = "a speed scale, speed bound or largest speed that is not finite and >= 0";
    if (!bad && !all_finite(ck->energy, ck->n_energy))
        bad = "a non-finite energy-budget term";
    if (!bad && !all_finite(ck->history, ck->n_pairs * ck->history_len))
        bad = "a non-finite pair history";
    for (size_t q = 0; !bad && q < np; q++) {
        const struct wetdem_checkpoint_pair* k = &ck->pairs[q];
        if (k->is_wall || !(k->i < k->j && k->j < n))
            bad = "a pair key that names no pair of its particles";
        else if (q > 0 && (k[-1].i > k->i || (k[-1].i == k->i && k[-1].j >= k->j)))
            bad = "pair keys out of (i, j) order"; /* restore_pairs merges them as sorted */
    }
    for (size_t q = 0; !bad && q < n * nw; q++) {
        const struct wetdem_checkpoint_pair* k = &ck->pairs[np + q];
        if (!k->is_wall || k->i != q / nw || k->j != q % nw)
            bad = "a particle-wall key out of order";
    }
    return bad ? wetdem_sim_fail(sim, WETDEM_ERR_PARSE, "checkpoint '%s': %s", path, bad)
               : WETDEM_OK;
}

/* Checks that checkpoint ck fits this sim's set-up. */
static int check_restorable(struct wetdem_sim* sim, const struct wetdem_checkpoint* ck,
                            const char* path)
{
    size_t n = ck->n_particles, nw = sim->n_walls;
    bool budget = sim->many->set.energy_budget;
    if (ck->config_hash != config_hash(sim) && ck->config_hash == config_hash_with(sim, !budget))
        return wetdem_sim_fail(sim, WETDEM_ERR_INVALID,
                               "checkpoint '%s' was written with the energy budget %s: resume "
                               "with it %s too (energy_budget = %s), or the budget would not "
                               "cover the whole run",
                               path, budget ? "off" : "on", budget ? "off" : "on",
                               budget ? "no" : "yes");
    if (ck->config_hash != config_hash(sim))
        return wetdem_sim_fail(sim, WETDEM_ERR_INVALID,
                               "checkpoint '%s' was written with different materials, fluid, "
                               "models, parameters, walls or many settings",
                               path);
    if (ck->n_walls != nw || ck->history_len != sim->history_len ||
        !blob_size_fits(ck->extra_size, n) ||
        (ck->n_energy != N_ENERGY && ck->n_energy != N_ENERGY_RIGHT_SUM) || ck->n_pairs < n * nw)
        return wetdem_sim_fail(sim, WETDEM_ERR_PARSE, "checkpoint '%s': inconsistent contents",
                               path);
    for (size_t k = 0; k < n; k++) {
        const struct wetdem_particle* p = &ck->particles[k];
        char why[256]; /* what wetdem_sim_add_particle accepts */
        if (!wetdem_sim_particle_valid(sim, p, why, sizeof why))
            return wetdem_sim_fail(sim, WETDEM_ERR_PARSE, "checkpoint '%s': particle %zu: %s", path,
                                   k, why);
    }
    return check_restorable_values(sim, ck, path);
}

/* The first step after `step` on the grid of `every` (0: no such output). */
static uint64_t next_on_grid(uint64_t step, unsigned long long every)
{
    return every ? (step / every + 1) * every : 0;
}

/* Particles, engine time and counters from ck. */
static int restore_state(struct wetdem_sim* sim, const struct wetdem_checkpoint* ck)
{
    struct wetdem_many* m = sim->many;
    size_t n = ck->n_particles;
    if (n > sim->particles_cap) {
        struct wetdem_particle* p = realloc(sim->particles, n * sizeof *p);
        if (!p)
            return wetdem_sim_fail(sim, WETDEM_ERR_NOMEM, "out of memory");
        sim->particles = p;
        sim->particles_cap = n;
    }
    if (n)
        memcpy(sim->particles, ck->particles, n * sizeof *sim->particles);
    sim->n_particles = n;
    sim->engine.time = sim->engine.t_committed = ck->time;
    sim->engine.stats = ck->stats;
    m->step = ck->step;
    memcpy(&m->dt, ck->extra, 8);
    memcpy(&m->t0, ck->extra + 8, 8);
    int st = wetdem_sim_many_time_scales(sim); /* not in the checkpoint */
    if (st != WETDEM_OK)
        return st;
    m->energy.k0 = ck->energy[0];
    m->energy.u0 = ck->energy[1];
    m->energy.el0 = ck->energy[2];
    memcpy(m->energy.work_pair, ck->energy + 3, sizeof m->energy.work_pair);
    memcpy(m->energy.work_wall, ck->energy + 3 + WETDEM_MAX_MODELS, sizeof m->energy.work_wall);
    /* a checkpoint of the right-sum accounting (no latest-pass terms) keeps reporting as it
       did: its work was summed without the first half and is reported whole */
    memset(m->energy.last_pair, 0, sizeof m->energy.last_pair);
    memset(m->energy.last_wall, 0, sizeof m->energy.last_wall);
    if (ck->n_energy == N_ENERGY) {
        memcpy(m->energy.last_pair, ck->energy + 3 + 2 * WETDEM_MAX_MODELS,
               sizeof m->energy.last_pair);
        memcpy(m->energy.last_wall, ck->energy + 3 + 3 * WETDEM_MAX_MODELS,
               sizeof m->energy.last_wall);
    }
    for (size_t k = 0; k < m->n_series; k++)
        free(m->vtk_names[k]);
    m->n_series = 0;
    m->vtk_files = ck->output.vtk_files; /* numbering continues: no frame is overwritten */
    m->csv_rows = ck->output.csv_rows;
    /* the outputs after the checkpoint follow the grid of this run's intervals, which may
       differ from those of the run that wrote it (the checkpoint's next steps are that run's;
       with the same intervals the two agree) */
    m->next_vtk_step = next_on_grid(m->step, m->set.vtk_every);
    m->next_csv_step = next_on_grid(m->step, m->set.csv_every);
    m->next_checkpoint_step = next_on_grid(m->step, m->set.checkpoint_every);
    return WETDEM_OK;
}

/* Pair histories: the checkpoint's pair list becomes the "previous" list of a forced rebuild,
 * which carries the histories over by key; wall histories are copied. Then the forces and
 * torques of the latest evaluation are restored. */
static int restore_pairs(struct wetdem_sim* sim, const struct wetdem_checkpoint* ck)
{
    struct wetdem_many* m = sim->many;
    size_t n = ck->n_particles, nw = sim->n_walls, len = sim->history_len;
    size_t np = ck->n_pairs - n * nw;
    m->started = false; /* prepare() re-initialises the cell list */
    m->cl.n_pairs = 0;
    m->records_stale = false; /* the records hold the checkpoint's state: load it */
    int st = wetdem_sim_many_prepare(sim);
    if (st != WETDEM_OK)
        return st;
    struct wetdem_celllist_pair* pairs = malloc((np ? np : 1) * sizeof *pairs);
    if (!pairs)
        return wetdem_sim_fail(sim, WETDEM_ERR_NOMEM, "out of memory");
    for (size_t q = 0; q < np; q++)
        pairs[q] =
            (struct wetdem_celllist_pair){(uint32_t)ck->pairs[q].i, (uint32_t)ck->pairs[q].j};
    double fresh[WETDEM_HISTORY_SCRATCH];
    if (len)
        wetdem_sim_history_init(sim, fresh);
    wetdem_celllist_remap_history(pairs, ck->history, np, m->cl.pairs, m->history, m->cl.n_pairs,
                                  len, fresh);
    free(pairs);
    if (len && n * nw > 0)
        memcpy(m->wall_history, ck->history + np * len, n * nw * len * sizeof(double));
    for (size_t k = 0; k < n; k++) {
        double ft[6];
        memcpy(ft, ck->extra + 16 + k * 48, 48);
        m->force[k] = vec3(ft[0], ft[1], ft[2]);
        m->torque[k] = vec3(ft[3], ft[4], ft[5]);
    }
    if (n && blob_has_images(ck->extra_size, n)) /* (prepare zeroed them: older layouts) */
        memcpy(m->image, ck->extra + blob_size(n), n * sizeof *m->image);
    if (ck->extra_size == blob_size_speeds(n)) { /* (older layouts: time_scales' at this state) */
        double speeds[3];
        memcpy(speeds, ck->extra + blob_size_images(n), BLOB_SPEEDS);
        m->speed_scale = speeds[0];
        m->speed_bound = speeds[1];
        m->v2_seen = speeds[2];
        /* the time scales at that speed scale, as the run that wrote it reported them (and
           its summary and warnings judged its step by), not at this state's */
        st = wetdem_sim_many_time_scales_at_scale(sim);
        if (st != WETDEM_OK)
            return st;
    }
    for (size_t q = 0; q < m->cl.n_pairs; q++) /* histories may be stale: check on next use */
        m->flags[q] = WETDEM_MANY_DIRTY | WETDEM_MANY_SPRING;
    m->started = true;
    wetdem_sim_many_keep_models(sim);
    return WETDEM_OK;
}

static int read_checkpoint(struct wetdem_sim* sim, const char* path)
{
    if (!path)
        return wetdem_sim_fail(sim, WETDEM_ERR_INVALID, "read_checkpoint: NULL path");
    if (!sim->many)
        return wetdem_sim_fail(sim, WETDEM_ERR_INVALID,
                               "reading a checkpoint needs the many-particle mode "
                               "(wetdem_sim_set_many) set up as when it was written");
    struct wetdem_checkpoint ck;
    char msg[512];
    int st = wetdem_checkpoint_read(path, &ck, msg, sizeof msg);
    if (st != WETDEM_OK)
        return wetdem_sim_fail(sim, st, "%s", msg);
    st = check_restorable(sim, &ck, path);
    if (st == WETDEM_OK)
        st = restore_state(sim, &ck);
    if (st == WETDEM_OK)
        st = restore_pairs(sim, &ck);
    if (st == WETDEM_OK)
        st = reload_series(sim);
    if (st == WETDEM_OK) { /* (the note of an earlier restore goes, whatever this one's) */
        free(sim->many->restored_note);
        sim->many->restored_note = strdup(ck.note ? ck.note : "");
        if (!sim->many->restored_note)
            st = wetdem_sim_fail(sim, WETDEM_ERR_NOMEM, "out of memory");
    }
    wetdem_checkpoint_clear(&ck);
    return st;
}

/* ---- the public writers and readers, in the C locale (locale_guard.h) ---- */

enum file_call { WRITE_VTK, WRITE_VTK_LINKS, WRITE_CHECKPOINT, READ_CHECKPOINT };

/* Runs a public file call: a writer refuses a run whose models changed since it started (its
 * pair histories are laid out by them; the run's own outputs are written by calls that
 * checked), then the call runs in the C locale. */
static int file_call(struct wetdem_sim* sim, enum file_call call, const char* path, bool binary)
{
    static const char* const what[] = {"write_vtk", "links", "write_checkpoint", NULL};
    int st = what[call] ? wetdem_sim_many_check_report(sim, what[call]) : WETDEM_OK;
    if (st != WETDEM_OK)
        return st;
    struct wetdem_locale_guard g;
    if (wetdem_locale_guard_enter(&g) != WETDEM_OK)
        return no_c_locale(sim);
    switch (call) {
    case WRITE_VTK: st = write_vtk(sim, path, binary); break;
    case WRITE_VTK_LINKS: st = write_vtk_links(sim, path, binary); break;
    case WRITE_CHECKPOINT: st = write_checkpoint(sim, path); break;
    case READ_CHECKPOINT:
        st = read_checkpoint(sim, path); /* (the times of the .vtk.series file) */
        break;
    }
    wetdem_locale_guard_leave(&g);
    return st;
}

int wetdem_sim_write_vtk(struct wetdem_sim* sim, const char* path, bool binary)
{
    return file_call(sim, WRITE_VTK, path, binary);
}

int wetdem_sim_write_vtk_links(struct wetdem_sim* sim, const char* path, bool binary)
{
    return file_call(sim, WRITE_VTK_LINKS, path, binary);
}

int wetdem_sim_write_checkpoint(struct wetdem_sim* sim, const char* path)
{
    return file_call(sim, WRITE_CHECKPOINT, path, false);
}

int wetdem_sim_read_checkpoint(struct wetdem_sim* sim, const char* path)
{
    return file_call(sim, READ_CHECKPOINT, path, false);
}

const char* wetdem_sim_checkpoint_note(const struct wetdem_sim* sim)
{
    return sim && sim->many ? sim->many->restored_note : NULL;
}

/* ---- insertion ---- */

int wetdem_sim_insert(struct wetdem_sim* sim, const struct wetdem_insert_spec* spec)
{
    if (spec->material < 0 || spec->material >= sim->n_materials)
        return wetdem_sim_fail(sim, WETDEM_ERR_INVALID,
                               "insert.material %d does not exist (valid 0..%d)", spec->material,
                               sim->n_materials - 1);
    char msg[768];
    if (wetdem_insert_check(spec, msg, sizeof msg) != WETDEM_OK) /* before taking memory */
        return wetdem_sim_fail(sim, WETDEM_ERR_INVALID, "%s", msg);
    struct wetdem_particle* p = malloc((spec->n ? spec->n : 1) * sizeof *p);
    if (!p)
        return wetdem_sim_fail(sim, WETDEM_ERR_NOMEM, "out of memory for %zu particles", spec->n);
    size_t n_before = sim->n_particles;
    int st =
        wetdem_insert_particles_among(spec, sim->particles, sim->n_particles, p, msg, sizeof msg);
    if (st != WETDEM_OK)
        st = wetdem_sim_fail(sim, st, "%s", msg);
    for (size_t k = 0; st == WETDEM_OK && k < spec->n; k++)
        st = wetdem_sim_add_particle(sim, p[k]);
    if (st != WETDEM_OK) /* (a sphere refused: e.g. a velocity drawn beyond the doubles) */
        sim->n_particles = n_before;
    free(p);
    return st;
}
