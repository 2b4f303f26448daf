/*
 * many.h — internal state of the many-particle mode of the soft engine (sim_many.c,
 * sim_many_io.c). The public settings are struct wetdem_many_settings in wetdem.h.
 */
#ifndef WETDEM_MANY_H
#define WETDEM_MANY_H

#include "celllist.h"
#include "sim.h"
#include "vec3.h"

/* Mixed properties of one material pair (as struct wetdem_contact) and the range of the
 * enabled models for it. */
struct wetdem_many_mix {
    double e_star, g_star;                          /* [Pa] */
    double restitution, friction_dry, friction_lub; /* [-] */
    double roughness, film;                         /* [m] */
    double viscosity, surface_tension;              /* [Pa s], [N/m] */
    double range; /* largest model range [m]: exact with the fused kernel, else the reach */
    /* damping coefficients of the restitution, computed once (force_hertz.c, force_mindlin.c):
       hertz by damping form (0 exact, 1 tsuji) [-] and the Mindlin factor [-]; NAN when the
       restitution is outside (0, 1] (the kernel reports that before using them) */
    double hertz_damping[2], mindlin_damping;
    double film_h_min; /* thin_film_h_min(h_min, film) of the lean kernel's constant h_min [m] */
};

/* The lean pair kernel (sim_many_force.c): for the model sets of the fused kernel without an
 * energy budget, the pair's force computed straight from the particles, without a struct
 * wetdem_contact, with the same arithmetic in the same order (bit-identical). */
struct wetdem_many_lean {
    bool on;            /* usable: fused models, valid restitutions, constant h_min */
    int hertz_form;     /* damping form of hertz (0 exact, 1 tsuji), -1 without hertz */
    bool mindlin;       /* mindlin enabled */
    bool mindlin_lub;   /* mindlin limits with friction_lub (else friction_dry) */
    size_t mindlin_off; /* its history offset [doubles] */
    bool sb;            /* sb enabled */
    double sb_below;    /* its below_hmin treatment */
    double h_min;       /* h_min of the constant min-separation model [m] */
    bool capillary;     /* capillary enabled */
    int n_normal;       /* models adding to the normal force, in model order: */
    unsigned char normal[WETDEM_MAX_MODELS]; /* 0 hertz, 1 sb, 2 capillary */
};

/* Result of one candidate pair at the latest force evaluation. */
struct wetdem_many_pair_out {
    struct wetdem_vec3 force;    /* on i (j receives the opposite) [N] */
    struct wetdem_vec3 torque_i; /* [N m] */
    struct wetdem_vec3 torque_j; /* [N m] */
};

/* Fewest particles for which the many-mode loops run in parallel: below it, waking the
 * threads costs more than the work (a 5-sphere chain ran 35x slower on 2 threads). The result
 * does not depend on the thread count either way. */
#define WETDEM_MANY_PARALLEL_MIN 512

/* The skip times are kept while at least 1/WETDEM_MANY_SKIP_SHARE of the candidates are
 * skipped (struct wetdem_many, skip_until). */
#define WETDEM_MANY_SKIP_SHARE 8

/* Most threads (blocks) of the force pass. */
#define WETDEM_MANY_MAX_BLOCKS 256

/* The flags of a candidate pair, what the force pass itself reads of its latest evaluation;
 * the contacts and bridges reported are the models' (wetdem_sim_many_links), worked out from
 * the state when they are reported. (4 is free: it marked gap < film, which only the reports
 * read before they followed the models.) */
#define WETDEM_MANY_ACTIVE 1u  /* within the interaction range: force applied */
#define WETDEM_MANY_CONTACT 2u /* gap < 0: solid overlap (the pair's torques and spring) */
#define WETDEM_MANY_DIRTY 8u   /* history may differ from a fresh one (reset when out of range) */
#define WETDEM_MANY_SPRING                                                                         \
    16u /* its tangential spring may be non-zero: set in solid contact,
                                  kept across rebuilds and restarts; the lean kernel resets the
                                  spring of a pair apart only then (else it is zero already) */

/* The set bits of a 4-bit mask, in order: its lanes (then zeros) and their number; for the
 * compaction of four lanes without a branch per lane (sim_many_force.c due_candidates,
 * many_bulk.h bulk_four). */
static const uint32_t wetdem_many_mask_lanes[16][4] = {
    {0, 0, 0, 0}, {0, 0, 0, 0}, {1, 0, 0, 0}, {0, 1, 0, 0}, {2, 0, 0, 0}, {0, 2, 0, 0},
    {1, 2, 0, 0}, {0, 1, 2, 0}, {3, 0, 0, 0}, {0, 3, 0, 0}, {1, 3, 0, 0}, {0, 1, 3, 0},
    {2, 3, 0, 0}, {0, 2, 3, 0}, {1, 2, 3, 0}, {0, 1, 2, 3}};
static const unsigned char wetdem_many_mask_count[16] = {0, 1, 1, 2, 1, 2, 2, 3,
                                                         1, 2, 2, 3, 2, 3, 3, 4};

/* Four pairs at a time (many_bulk.h): what the bulk evaluation of a block's listed
 * candidates reads, and what it gives per candidate. For the lean kernel with a film model in
 * the common case (one material pair, no periodic axis). */
#define WETDEM_MANY_BULK_MAX 64 /* candidates per call (a multiple of 4) */
struct wetdem_many_bulk_in {
    const struct wetdem_celllist_item* xr;
    const struct wetdem_vec3 (*vw)[2];
    const struct wetdem_vec3 (*vwh)[2]; /* the half-step ones (struct wetdem_many vwh) */
    const struct wetdem_celllist_pair* pairs;
    const double* lim2;             /* pair_lim2 */
    double film, film_h_min, range; /* of the material pair [m] */
    bool axis_periodic[3];          /* the periodic axes (d = x_i - x_j is the minimum image
                                       there), of lengths box_len [m] */
    double box_len[3];
    double sb_coef;            /* 6 pi mu [Pa s] */
    double cap_coef;           /* 8 pi */
    double surface_tension;    /* [N/m] */
    bool sb, sb_nc, capillary; /* sb and capillary enabled; sb's "nc" treatment below h_min' */
    /* then the solid contacts (gap < 0) among them (many_bulk.h bulk_contacts), with the lean
       kernel's plan: hertz (form 0 exact, 1 tsuji, -1 absent), mindlin, the normal forces in
       model order (0 hertz, 1 sb, 2 capillary) */
    int hertz_form;
    bool mindlin;
    int n_normal;
    unsigned char normal[WETDEM_MAX_MODELS];
    bool budget;              /* an energy budget: also each model's terms (out's hertz and
                                 f_tan) */
    const double (*cache)[4]; /* pair_cache: R* [m], m* [kg], Hertz k, damping factor */
    double* history;          /* the pair histories, len doubles each; the Mindlin spring at */
    size_t len, spring_off;   /* spring_off of them [m] */
    double dt;                /* [s] */
    double g_star, mu;        /* G* [Pa] and the Coulomb coefficient of the Mindlin limit [-] */
    double tangential_factor; /* the Mindlin damping factor -2 sqrt(5/6) beta [-] */
    /* particle-wall pairs four at a time (many_bulk.h bulk_walls) */
    const struct wetdem_wall* walls;
    size_t n_walls;
    double* wall_history; /* n_walls x len doubles per particle */
    const double* m_eff;  /* per particle: its mass against a wall [kg] (contact.h) */
    double e_star;        /* E* [Pa] */
    double hertz_coef;    /* the damping coefficient of hertz's form [-] */
};
struct wetdem_many_bulk_out { /* by component, each entry 32-byte aligned */
    /* 0: beyond the gap test's reach (|x_i - x_j|^2 > pair_lim2); 1: within it, for the scalar
       kernel; else its flags: apart within the range with a finite force, or in solid contact
       with a finite force and torques, its spring stored */
    long long cls[WETDEM_MANY_BULK_MAX] __attribute__((aligned(32)));
    uint32_t i[WETDEM_MANY_BULK_MAX], j[WETDEM_MANY_BULK_MAX];       /* the pair's particles */
    double r2[WETDEM_MANY_BULK_MAX] __attribute__((aligned(32)));    /* |x_i - x_j|^2 [m^2] */
    double gap[WETDEM_MANY_BULK_MAX] __attribute__((aligned(32)));   /* [m] */
    double n[3][WETDEM_MANY_BULK_MAX] __attribute__((aligned(32)));  /* unit normal, j to i */
    double v_n[WETDEM_MANY_BULK_MAX] __attribute__((aligned(32)));   /* [m/s] */
    double f_sb[WETDEM_MANY_BULK_MAX] __attribute__((aligned(32)));  /* its sb term [N] */
    double f_cap[WETDEM_MANY_BULK_MAX] __attribute__((aligned(32))); /* its capillary term [N] */
    /* with in->budget: the hertz term [N] and mindlin's tangential force on i [N] (lean_force's
       term[0] and f_tan), +0 apart (and so the torque on j) */
    double hertz[WETDEM_MANY_BULK_MAX] __attribute__((aligned(32)));
    double f_tan[3][WETDEM_MANY_BULK_MAX] __attribute__((aligned(32)));
    double force[3][WETDEM_MANY_BULK_MAX] __attribute__((aligned(32))); /* its force on i [N] */
    /* in solid contact (cls has WETDEM_MANY_CONTACT): the torques on i and j [N m]; the one
       on i is +0 for the other pairs evaluated */
    double torque_i[3][WETDEM_MANY_BULK_MAX] __attribute__((aligned(32)));
    double torque_j[3][WETDEM_MANY_BULK_MAX] __attribute__((aligned(32)));
};
typedef void wetdem_many_bulk_fn(const struct wetdem_many_bulk_in* in, const uint32_t* list,
                                 size_t n, size_t j_end, struct wetdem_many_bulk_out* out);
/* Particle-wall pairs (part[e], wall[e]) within the range, at gap[e] [m] (e < n <=
 * WETDEM_MANY_BULK_MAX): cls (1 for the scalar kernel, else the flags), force and torque_i. */
typedef void wetdem_many_bulk_walls_fn(const struct wetdem_many_bulk_in* in, const uint32_t* part,
                                       const unsigned char* wall, const double* gap, size_t n,
                                       struct wetdem_many_bulk_out* out);
/* many_bulk.c: the baseline version; many_bulk_avx2.c: the AVX2 one; many_bulk_avx512.c: the
   same in the AVX-512 encoding (both x86-64 with GCC). */
wetdem_many_bulk_fn wetdem_many_bulk_base, wetdem_many_bulk_avx2, wetdem_many_bulk_avx512;
wetdem_many_bulk_walls_fn wetdem_many_bulk_base_walls, wetdem_many_bulk_avx2_walls,
    wetdem_many_bulk_avx512_walls;
/* The versions by instruction set; BEST: the last of them that the processor runs. */
enum wetdem_many_bulk_isa {
    WETDEM_MANY_BULK_BEST,
    WETDEM_MANY_BULK_BASE,
    WETDEM_MANY_BULK_AVX2,
    WETDEM_MANY_BULK_AVX512
};
/* Whether the processor (and its operating system) runs version `isa` (BEST and BASE always). */
bool wetdem_many_bulk_usable(enum wetdem_many_bulk_isa isa);
/* Version `isa` where usable, else the baseline one. */
wetdem_many_bulk_fn* wetdem_many_bulk_choose(enum wetdem_many_bulk_isa isa);
/* Whether a film model acts in a four-at-a-time pass with input in: then its results mix
 * contacts and bridges apart (many_bulk.h bulk_films_of, sim_many_force.c pairs_of_block). */
static inline bool wetdem_many_bulk_films(const struct wetdem_many_bulk_in* in)
{
    return (in->sb || in->capillary) && in->film > 0;
}
wetdem_many_bulk_walls_fn* wetdem_many_bulk_walls_choose(enum wetdem_many_bulk_isa isa);

/* Energy bookkeeping (sim_many.c accumulates, sim_many_io.c reports). */
/* The work is summed by the trapezoid rule over the force passes, dt (P_0/2 + P_1 + ... +
 * P_{N-1} + P_N/2) with P_n the power of the forces of pass n: each force changes the kinetic
 * energy through two half kicks, and the forces of the first and of the latest pass have given
 * only one. work_* hold dt (P_0/2 + P_1 + ... + P_N) and last_* the latest pass's dt P_N, of
 * which wetdem_sim_energy_budget takes half off (sim_many.c). */
struct wetdem_many_energy {
    double k0, u0, el0;                  /* kinetic, potential, elastic at the start [J] */
    double work_pair[WETDEM_MAX_MODELS]; /* work of model k on particle pairs [J] */
    double work_wall[WETDEM_MAX_MODELS]; /* work of model k on particle-wall pairs [J] */
    double last_pair[WETDEM_MAX_MODELS]; /* the latest pass's part of work_pair [J] */
    double last_wall[WETDEM_MAX_MODELS]; /* the latest pass's part of work_wall [J] */
};

struct wetdem_many {
    struct wetdem_many_settings set; /* copy; the strings below are owned copies */
    char* output_prefix;
    char* checkpoint_path;
    char* csv_comment;
    char* checkpoint_note; /* written into every checkpoint (NOTE section) */
    char* restored_note;   /* the note of the checkpoint restored last; NULL: none restored */
    struct wetdem_celllist cl;
    double reach; /* largest interaction gap of any pair [m] (start-up bound) */
    /* With a min-separation model that keeps a record beyond the force range (its record_range
       hook: ehd, max, glass), `record` is set and the pairs' records live up to that range
       (sim_models.c wetdem_sim_history_beyond_range): the cell list's reach (cl.reach) is then
       the larger of `reach` and the largest record range of two spheres, and wall_reach that
       of `reach` and the largest record range of a sphere and a wall, so that no pair or wall
       with a live record leaves the lists. Without it, cl.reach = wall_reach = reach. [m] */
    bool record;
    /* record and the min-separation model one of wetdem's own (ehd, max, glass), which read of
       a contact only its gap, R*, v_n and mixed properties: a pair beyond the force range may
       then be given that part of its contact alone (sim_many_force.c, record_only) */
    bool record_partial;
    double wall_reach;
    double dt;              /* time step [s], fixed once the many run starts */
    double advance;         /* the time the tangential springs advance in a force pass [s]: dt,
                               but 0 in the first pass of a run, the forces at t0, which no
                               motion has moved yet (as the two-body engine's c.dt = 0); that
                               pass keeps none of the histories it writes (sim_many_force.c) */
    char dt_origin[384];    /* what sets dt, for messages (choose_dt; "" after a restore) */
    double relaxation_time; /* shortest viscous relaxation time at the start [s] (choose_dt),
                               or when the run was restored from a checkpoint */
    double contact_time;    /* shortest contact time, normal or tangential, then [s] */
    double crossing_time;   /* time to close the smallest h_min where the force laws jump at
                               the speed scale, then [s] (INFINITY: none jumps) */
    double v2_drift;        /* largest |v'|^2 of the latest drift [m^2/s^2] (after_drift) */
    /* the speed scale of the time scales above and the speed no particle exceeds under it
       (wetdem_many_stats speed_scale, speed_bound) [m/s], and the largest |v'|^2 of the drifts
       since the start [m^2/s^2]: set when the run starts, kept by a checkpoint */
    double speed_scale, speed_bound, v2_seen;
    double t0;     /* time of step 0 [s] */
    uint64_t step; /* steps since t0 */
    bool started;
    /* the force models of the run and its min-separation model, in order, as it started (or
       was restored): its pair histories are laid out and its work summed by them, so a call
       or a report after they changed is refused (sim_many.c wetdem_sim_many_check_models) */
    const struct wetdem_model* run_models[WETDEM_MAX_MODELS + 1];
    size_t run_n_models;
    /* wall time by phase in this process [s] (wetdem_many_stats): kicks and drifts, force
       passes (less their list builds), neighbour-list builds, outputs and observers */
    double seconds_kick, seconds_forces, seconds_lists, seconds_output;
    double* history; /* cl.n_pairs x history_len, aligned with cl.pairs */
    size_t history_cap;
    double* wall_history; /* n_particles x n_walls x history_len */
    size_t wall_history_cap;
    /* the particles and walls wall_history is laid out for (sim_many.c layout_wall_history):
       walls may be added between calls, which widens every particle's row */
    size_t wall_history_n, wall_history_walls;
    struct wetdem_celllist_pair* old_pairs; /* previous list, for history remapping */
    double* old_history; /* their histories; in the first pass of a run, the histories (pairs,
                            then walls) as given, put back after it (sim_many_force.c) */
    size_t old_cap, old_history_cap;
    unsigned char* flags; /* per candidate pair: MANY_ACTIVE | _CONTACT | _DIRTY | _SPRING
                                    (a separate byte array: the gather scans it densely) */
    size_t flags_cap;
    /* constants of each candidate pair, computed once per list build and kernel set-up (the
       radii, masses and ranges do not change in between; sim_many_force.c pair_constants):
       the gap test's bound (R_i + R_j + r_ab)^2 (1 + margin) [m^2], and for the lean kernel
       R* [m], m* [kg], the Hertz stiffness (4/3) E* sqrt(R*) [N/m^1.5] and the damping factor
       c sqrt(m* k) of the hertz form [kg/(s m^0.25)] */
    double* pair_lim2;
    double (*pair_cache)[4];
    size_t pair_lim2_cap, pair_cache_cap;
    /* The gap test's skip clock (sim_many_force.c gap_test): drift_clock is the sum since the
       list build of every step's bound on the displacement of any particle (sim_many.c
       kick_drift) [m], so two particles have come closer by at most twice its growth. A
       candidate rejected at clock c with |d| - far = g > 0 cannot pass the test while the
       clock is below c + g/2, its skip_until; until then it is not tested (its result would be
       the same: a rejection). The times are kept (skip_on) from each list build, and again
       32 passes after they were dropped (skip_off_passes), for as long as at least an eighth
       of the candidates are skipped (in a flowing system few are, and keeping the times costs
       more than the skips save; with half, as before, a wet packing lost them too often:
       5 % more instructions on the benchmark's shared state). They are usable (skip_ready)
       when the previous pass kept them and every step since had a bound; a list build, a
       call, particles loaded anew, a step without a bound and a restart of the clock clear
       it. */
    float* skip_until; /* [m], rounded down */
    size_t skip_until_cap;
    /* The constants of the skip times, per list build (sim_many_force.c pair_constants and
       within_reach). With far_q = sqrt(pair_lim2) (1 + 1e-9) + 1e-12 (x_build_max + skin)
       [m], the distance beyond which the gap test rejects candidate q with room to spare for
       every round-off, and d_max the largest far_q plus the skin, a rejected candidate at
       squared distance r2 has |d| - far_q >= min((r2 - far_q^2) / (2 d_max), skin): that is
       (|d|^2 - far_q^2) / (|d| + far_q) with the denominator at most 2 d_max, or, beyond
       d_max, more than the skin. far_q^2 <= pair_lim2 rel + abs; no square root per
       candidate. rel [-], abs [m^2], inv_2dmax = 1 / (2 d_max) rounded down [1/m], cap = the
       skin [m]. */
    struct skip_bound {
        double rel, abs, inv_2dmax, cap;
    } skip_bound;
    double drift_clock;
    bool skip_on, skip_ready;
    unsigned skip_off_passes;
    bool no_skip;             /* tests: test every candidate at every pass */
    bool skip_always;         /* tests: keep the times whatever share is skipped */
    unsigned skip_share;      /* tests: keep them while 1/skip_share are skipped (0: the
                                 default, 1/WETDEM_MANY_SKIP_SHARE) */
    double clock_limit;       /* tests: restart the skip clock beyond this [m] (0: the skin) */
    uint64_t clock_restarts;  /* restarts of the skip clock (tests) */
    uint64_t pass_candidates; /* candidates of the latest pass's gap tests */
    uint64_t pass_skipped;    /* of which skipped */
    uint64_t skipped_tests;   /* candidates not tested thanks to the clock (tests) */
    /* With usable skip times, the tested candidates of a block are either gap-tested in one
       flat loop and the kernels run over the list of those within range (two loops), or, when
       most of them are within range (a slow or resting packing, where the far candidates are
       skipped), tested and evaluated in one loop, their geometry computed once (fused). The
       latest pass decides: fused when at least 3/4 of the tested candidates (pass_candidates
       less pass_skipped) were within range. Either way the same kernels run in the same order
       (sim_many_force.c). */
    uint64_t pass_near; /* in-block candidates of the latest pass within range */
    bool fuse_on;       /* the next pass with usable skip times runs fused */
    int fuse_mode;      /* tests: 0 decided as above, 1 never fused, 2 always fused */
    bool bulk_off;      /* tests: never four pairs at a time (many_bulk.h) */
    /* tests: the version of four pairs at a time where it applies (default BEST) */
    enum wetdem_many_bulk_isa bulk_isa;
    uint64_t fused_passes;      /* passes run fused (tests) */
    uint64_t bulk_passes;       /* passes with four pairs at a time (tests) */
    uint64_t bulk_contacts;     /* solid contacts evaluated four at a time (tests) */
    uint64_t bulk_walls;        /* particle-wall pairs within range evaluated so (tests) */
    uint64_t pair_consts_build; /* the list build they were computed for */
    bool pair_consts_ready;     /* cleared when the kernel is set up */
    unsigned char* old_flags;   /* flags of the previous list, for remapping */
    size_t old_flags_cap;
    uint64_t* wall_mask; /* per particle: bit w set if wall w is within wall_reach + skin
                                    at the last build (walls >= 64 are always evaluated) */
    size_t wall_mask_cap;
    size_t walls_masked;  /* walls when the masks were made: one added since needs a build */
    uint64_t* wall_dirty; /* per particle: bit w set if the history of wall w may differ
                                    from a fresh one (walls >= 64: always treated as set); all
                                    set when a run (re)starts (sim_many.c prepare) */
    uint32_t* wall_list;  /* particles with a non-zero wall_mask (or all if > 64 walls) */
    size_t n_wall_list, wall_list_cap;
    /* with at most 64 walls: the bits of the masks as a flat list of particle-wall pairs, in
       particle order and, for each particle, in wall order (e < n_wall_entries) */
    uint32_t* wall_entry_part;
    unsigned char* wall_entry_wall;
    size_t n_wall_entries, wall_entry_part_cap, wall_entry_wall_cap;
    bool kick_pending;      /* the latest step's closing half kick is still to be applied
                                    (sim_many.c one_step); never true outside a run */
    size_t sums_zeroed;     /* the kick-drift pass set force and torque of this many
                                    particles to zero (0: not); the next force pass then starts
                                    only the sums of the particles with walls */
    double disp_bound;      /* upper bound of the largest displacement since the build [m]
                                    (sim_many.c kick_drift; 0 at a build, INFINITY when a call
                                    starts) */
    double x_build_max;     /* the largest |coordinate| at the build [m] */
    uint64_t disp_measures; /* displacement measurements so far (tests) */
    double max_disp2;       /* largest squared displacement since the build [m^2], */
    bool max_disp_valid;    /* measured during the latest drift */
    /* The next step's kick and drift inside the force pass (WETDEM_MANY_END_STEP, sim_many.c
       one_step): drifted, the latest pass did them, so the next step starts at its force pass
       (also after a failed pass, whose state is that of the next step begun); drift_v2[b] the
       largest |v'|^2 of block b's drift (b < n_blocks); drift_seconds the master thread's time
       in them; drift_passes the passes that did so (tests). Tests: no_drift_in_pass keeps the
       kick-drift pass at every step; a non-zero stop_during_step raises the stop flag during
       that step's force pass, as a signal arriving then would. */
    bool drifted, no_drift_in_pass;
    double drift_v2[WETDEM_MANY_MAX_BLOCKS];
    double drift_seconds;
    uint64_t drift_passes, stop_during_step;
    /* blocks of the force pass (sim_many_force.c), one per thread: particles blk[b] ..
       blk[b+1]; the pairs crossing blocks (first particle in an earlier block), in pair order
       (cross_q, with their results cross_out), grouped by the block of the first particle
       (cross_first[b] ..) and, through cross_in, by the block of the second particle
       (cross_first[n_blocks + 1 + b] ..) ordered by (second, first) */
    size_t *blk, *cross_first;
    uint32_t *cross_q, *cross_in;
    struct wetdem_many_pair_out* cross_out;
    /* scratch of the force pass, per pair: the candidates within range or with flags, and for
       each entry whether it is within range (1) or listed for its flags (0) */
    uint32_t* hits;
    unsigned char* hit_near;
    size_t hits_cap, hit_near_cap;
    size_t blk_cap, cross_first_cap, cross_q_cap, cross_in_cap, cross_out_cap;
    size_t n_blocks, blocks_n;
    uint64_t blocks_build;  /* list build the blocks were indexed for */
    uint64_t blocks_passes; /* force passes since the blocks were indexed */
    bool blocks_refined;    /* re-indexed since the list build, with flags from a pass */
    double block_est[WETDEM_MANY_MAX_BLOCKS];  /* estimated work of each block */
    double block_time[WETDEM_MANY_MAX_BLOCKS]; /* its time in the passes since [s] */
    /* the kick-drift pass's ranges (sim_many.c kick_ranges): thread t updates the particles
       kick_cut[t] .. kick_cut[t + 1], cut by the speed each range was updated at (smoothed) */
    size_t kick_cut[WETDEM_MANY_MAX_BLOCKS + 1];
    double kick_speed[WETDEM_MANY_MAX_BLOCKS]; /* [particles/s]; 0 before a measurement */
    size_t kick_threads, kick_n;               /* the ranges' count, and the particles */
    double* work;                              /* per particle: scratch of the partition */
    size_t work_cap;
    bool blocks_ready;
    /* force kernel (sim_many_force.c) */
    struct wetdem_many_mix* mix; /* n_mix_materials^2 material pairs */
    size_t mix_cap;
    int n_mix_materials;
    struct wetdem_many_lean lean; /* the lean pair kernel's plan */
    bool kernel_ready;            /* mix and kind[] match the current set-up */
    bool fused;                   /* every enabled model has a fused kernel */
    bool generic_only;            /* tests: never use the fused kernel */
    uint64_t block_jitter; /* tests: non-zero cuts the force-pass blocks at random (a seed) */
    uint64_t kick_jitter;  /* tests: non-zero cuts the kick-drift ranges at random (a seed) */
    size_t parallel_min;   /* tests: fewest particles for parallel loops (0: default
                                    WETDEM_MANY_PARALLEL_MIN) */
    bool periodic_any;     /* some axis is periodic */
    unsigned char kind[WETDEM_MAX_MODELS]; /* fused kernel of model k */
    double kind_opt[WETDEM_MAX_MODELS];    /* its switch parameter (hertz damping form, ...) */
    struct wetdem_vec3 *force, *torque;    /* per particle */
    /* per particle: velocity and spin at the half step, v' and w' of the latest drift (a fixed
       particle's own); the tangential springs advance with the slip they give (midpoint rule:
       sim_many_force.c, many_bulk.h) */
    struct wetdem_vec3 (*vwh)[2];
    /* The engine state of a run: per particle, position and radius (xr, also what the gap
       tests read) and velocity and spin (vw; the predicted v' + a dt/2 during a force pass).
       Loaded from the particle records when a call starts (wetdem_sim_many_prepare), and
       written back to them (records_stale cleared) whenever the state can be read: after a
       step that is not deferred, at a stop, at the end of a call, at a failure; and the
       positions before a list build. Between, the steps touch only these compact arrays. */
    struct wetdem_celllist_item* xr;
    struct wetdem_vec3 (*vw)[2];
    unsigned char* fixed; /* per particle: is_fixed of the record */
    /* per particle: the box lengths its wraps on the periodic axes have taken off its position
       since the run started (x unwrapped = x + image L), so that gravity along a periodic axis
       keeps a continuous potential -m g . x unwrapped; restored from checkpoints. Whole
       numbers held as doubles (exact to 2^53; a diverging run's wrap counts, beyond any
       integer type, stay defined until the run stops on its non-finite state) */
    double (*image)[3];
    bool records_stale; /* the records' positions, velocities and spins are behind */
    double (*inv)[2];   /* per particle: 1/m [1/kg] and 1/I = 1/(0.4 m R^2) [1/(kg m^2)], computed
                         with the integrator's own expressions when a run (re)starts */
    double* m_eff;      /* per particle: contact_effective_mass (the mass, infinite if fixed) */
    size_t particle_cap;
    struct wetdem_many_energy energy;
    /* with an energy budget, the work of a force pass, model by model (n_models doubles per
       entry), summed in an order that does not depend on the blocks (sim_many_force.c
       collect_pass_work): per particle i of its pairs (i, j) and of its walls, and per cross
       pair, with its chunk sums */
    double *pair_work, *wall_work, *cross_work, *chunk_work;
    size_t pair_work_cap, wall_work_cap, cross_work_cap, chunk_work_cap;
    /* outputs */
    uint64_t vtk_files, csv_rows;
    uint64_t next_vtk_step, next_csv_step, next_checkpoint_step;
    char** vtk_names; /* the .vtk.series entries: file names and times [s] */
    double* vtk_times;
    size_t n_series, vtk_names_cap;
    size_t links_from; /* with vtk_links, the first entry with links (a run resumed with links
                          after it was written without has them from the restart on) */
};

/* Whether loops over n particles of m run in parallel. */
static inline bool wetdem_many_parallel(const struct wetdem_many* m, size_t n)
{
    return n >= (m->parallel_min ? m->parallel_min : WETDEM_MANY_PARALLEL_MIN);
}

/* Particle k with the engine state (position, velocity, spin) in place of its record's. */
static inline struct wetdem_particle wetdem_many_particle(const struct wetdem_sim* sim, size_t k)
{
    const struct wetdem_many* m = sim->many;
    struct wetdem_particle p = sim->particles[k];
    p.pos = (struct wetdem_vec3){m->xr[k].x, m->xr[k].y, m->xr[k].z};
    p.vel = m->vw[k][0];
    p.omega = m->vw[k][1];
    return p;
}

/* How many walls particle i can meet: none when it is fixed (a fixed sphere and a wall never
 * interact, as in pairs.c), else all. The loops over a particle's walls that read the state
 * (counts, links, elastic energy) stop there; the force pass's wall lists are built to it
 * (update_wall_masks). */
static inline size_t wetdem_many_walls_of(const struct wetdem_sim* sim, size_t i)
{
    return sim->particles[i].is_fixed ? 0 : sim->n_walls;
}

/* The committed history of candidate pair q, and of particle i with wall w (NULL without
 * history). */
static inline const double* wetdem_many_pair_history(const struct wetdem_sim* sim, size_t q)
{
    return sim->history_len ? sim->many->history + q * sim->history_len : NULL;
}
static inline const double* wetdem_many_wall_history(const struct wetdem_sim* sim, size_t i,
                                                     size_t w)
{
    return sim->history_len ? sim->many->wall_history + (i * sim->n_walls + w) * sim->history_len
                            : NULL;
}

/* Closing half kick of particle k with gravity g: v = v' + a dt/2, w = w' + alpha dt/2 from
 * the half-step velocities and the latest forces (the force pass, or a deferred kick before
 * the state is read; sim_many.c's kick-drift pass applies it with the same arithmetic). */
static inline void wetdem_many_close_kick(struct wetdem_many* m, size_t k, struct wetdem_vec3 g)
{
    if (m->fixed[k])
        return;
    double h = m->dt;
    m->vw[k][0] = vec3_axpy(m->vwh[k][0], 0.5 * h, vec3_axpy(g, m->inv[k][0], m->force[k]));
    m->vw[k][1] = vec3_axpy(m->vwh[k][1], 0.5 * h, vec3_scale(m->torque[k], m->inv[k][1]));
}

/* sim_many.c */
/* wetdem_sim_many_free and wetdem_sim_many_integrate: sim.h. */
/* Closing half kick of the deferred step, half kick and drift of particles lo .. hi - 1, their
 * force and torque zeroed for the next pass (the kick-drift pass's arithmetic);
 * returns their largest |v'|^2. */
double wetdem_sim_many_drift_range(struct wetdem_sim* sim, size_t lo, size_t hi);
/* Kinetic (translational + rotational) and gravitational potential energy at the current
 * state, and the elastic energy stored in the solid contacts of the enabled models at the
 * latest evaluation (wetdem_sim_contact_elastic_energy over the pairs and walls) [J]. */
void wetdem_sim_many_energies(const struct wetdem_sim* sim, double* kinetic, double* potential,
                              double* elastic);
/* Makes sure the pair list, histories and per-particle arrays fit the current particles
 * (builds the cell list when needed). */
int wetdem_sim_many_prepare(struct wetdem_sim* sim);
/* The time scales of the step for the current particles, as at the start of a run: sets
 * m->relaxation_time (what the step is held below; INFINITY when nothing damps),
 * m->contact_time and m->crossing_time (wetdem_many_stats), and m->speed_scale and
 * m->speed_bound at this state, with m->v2_seen = 0. Returns WETDEM_OK or WETDEM_ERR_NOMEM
 * (message in sim). */
int wetdem_sim_many_time_scales(struct wetdem_sim* sim);
/* The same time scales at the speed scale m->speed_scale rather than at this state's (a
 * restored run's, whose checkpoint keeps the start's speed scale: the time scales of the
 * run that wrote it, for the same spheres and materials); m->speed_scale, m->speed_bound and
 * m->v2_seen are left as they are. Returns WETDEM_OK or the error of the probes. */
int wetdem_sim_many_time_scales_at_scale(struct wetdem_sim* sim);

/* Records the enabled models as those of the run (run_models), when it starts or is restored. */
void wetdem_sim_many_keep_models(struct wetdem_sim* sim);
/* WETDEM_OK when the enabled force models and the min-separation model are those the started
 * run recorded (their parameters may change), else WETDEM_ERR_INVALID with a message naming
 * both sets, beginning with `what` (the call refused). */
int wetdem_sim_many_check_models(const struct wetdem_sim* sim, const char* what);
/* What a report of a started run requires (wetdem_sim_many_stats, wetdem_sim_many_speeds):
 * the many-particle mode, a started run and its models unchanged
 * (wetdem_sim_many_check_models). WETDEM_OK, or WETDEM_ERR_INVALID with "WHAT: why". */
int wetdem_sim_many_check_run(const struct wetdem_sim* sim, const char* what);
/* What a report of a started run reads besides the histories: its models unchanged
 * (wetdem_sim_many_check_models) and the particles as edited through wetdem_sim_particles()
 * since the latest call. WETDEM_OK when those hold and each particle is one the next call
 * accepts (wetdem_sim_particle_valid), or no run has started, else WETDEM_ERR_INVALID with
 * "WHAT: why" ("WHAT: particle K: why"), so that no report reads past the materials or sums a
 * NaN. */
int wetdem_sim_many_check_report(const struct wetdem_sim* sim, const char* what);

/* sim_many_force.c */
/* Builds the material-pair table and chooses the kernel (fused or generic); needs m->reach
 * and the cell-list box. WETDEM_OK or WETDEM_ERR_NOMEM. */
int wetdem_sim_many_setup_kernel(struct wetdem_sim* sim);
/* Mixed properties of materials a and b (setup_kernel must have run). */
const struct wetdem_many_mix* wetdem_sim_many_mix(const struct wetdem_sim* sim, int a, int b);
/* Contact of particle i with particle j (minimum image) or with wall j, properties from the
 * table (a material added since it was made: mixed on the spot, with the table's fluid): the
 * same values as wetdem_sim_build_contact (up to the rounding of the image's position across a
 * periodic face). */
void wetdem_sim_many_contact(const struct wetdem_sim* sim, size_t i, size_t j, bool is_wall,
                             struct wetdem_contact* c);
/* The fused kernel: the same contract and results as wetdem_sim_eval_contact, for model sets
 * of hertz, mindlin, sb and capillary only (m->fused); x: the mixed properties of the pair's
 * materials, from which c was built. */
int wetdem_sim_many_eval_fused(const struct wetdem_sim* sim, struct wetdem_contact* c,
                               const struct wetdem_many_mix* x, double* history,
                               struct wetdem_pair_force* out, struct wetdem_pair_force* per_model);
/* What a force pass does with each particle once its force is complete. */
enum wetdem_many_end {
    WETDEM_MANY_END_NONE, /* nothing: the closing half kick is left to the next step */
    WETDEM_MANY_END_KICK, /* the closing half kick v = v' + a dt/2 */
    WETDEM_MANY_END_STEP  /* the closing half kick, the next step's half kick and its drift
                             (wetdem_sim_many_drift_range), block by block */
};
/* Forces and torques of every particle at the current state, histories
 * committed, then `end` for each particle. */
int wetdem_sim_many_forces(struct wetdem_sim* sim, enum wetdem_many_end end);

/* sim_many_io.c */
/* Writes the outputs due at the current step (VTK, CSV, periodic checkpoint). */
int wetdem_sim_many_outputs(struct wetdem_sim* sim, bool final);
/* Contacts and liquid bridges at the latest force evaluation, as the enabled models define
 * them (wetdem_sim_contact_is_in_contact, wetdem_sim_contact_is_bridged; docs/many.md,
 * Outputs): into s, the particle pairs and particle-wall pairs in contact (contacts), the
 * particle pairs bridged (bridges), and the clusters of >= 2 particles joined by bridges,
 * found by union-find over the bridged pairs (agglomerates, mean_agglomerate); the other
 * fields are left as they are. per (optional, as each of its arrays, of n_particles entries)
 * receives each particle's contacts with particles and walls, its liquid bridges, and the
 * label of its agglomerate: 1, 2, ... in the order of the agglomerates' lowest particle index,
 * 0 for a particle in none. WETDEM_OK or WETDEM_ERR_NOMEM. */
struct wetdem_many_per_particle {
    uint32_t* contacts;
    uint32_t* bridges;
    uint32_t* agglomerate;
};
int wetdem_sim_many_links(const struct wetdem_sim* sim, const struct wetdem_many_per_particle* per,
                          struct wetdem_many_stats* s);

#endif
