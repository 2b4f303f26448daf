/*
 * wetdem.h — the one public header of libwetdem.
 *
 * wetdem simulates collisions of wet and immersed spheres with the discrete element method:
 * lubrication, thin-film viscous and capillary forces combined with soft (Hertz–Mindlin) or
 * hard-sphere (impulse) contact.
 *
 * Conventions (docs/concepts.md): SI units everywhere. For a pair i–j the unit normal points
 * from j to i, the gap h = |x_i - x_j| - R_i - R_j is negative when the solids overlap, the
 * normal approach speed v_n is positive when the surfaces approach, R* = R_i R_j/(R_i + R_j),
 * m* = m_i m_j/(m_i + m_j). A force reported for a pair acts on i; j receives the opposite.
 *
 * Status codes: 0 success, > 0 success with information, < 0 error (enum wetdem_status). The
 * library never exits or aborts; a failing call on a simulation stores a message that
 * wetdem_sim_errmsg() returns.
 *
 * Sections, in the order a user needs them: value types; status; parameters; materials;
 * models; simulation; pair forces; hard-sphere impulses; soft engine; analysis;
 * pairwise engine; tracking and fitting.
 */
#ifndef WETDEM_H
#define WETDEM_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

#if defined(__GNUC__)
#define WETDEM_API __attribute__((visibility("default")))
#else
#define WETDEM_API
#endif

#define WETDEM_VERSION "0.1.0"

/* ======================================================================================== */
/* Value types                                                                              */
/* ======================================================================================== */

struct wetdem_vec3 {
    double x, y, z;
};

/* One sphere. Plain data: safe to copy. */
struct wetdem_particle {
    struct wetdem_vec3 pos;   /* centre position [m] */
    struct wetdem_vec3 vel;   /* velocity [m/s] */
    struct wetdem_vec3 omega; /* angular velocity [rad/s] */
    double radius;            /* [m], > 0 */
    double mass;              /* [kg], > 0; 0 means "from the material density" when added */
    int material;             /* index into the simulation's material table */
    bool is_fixed;            /* held in place (infinite mass), e.g. a target on a support */
};

/* Solid and film properties of one material. All per particle; pairs mix them
 * (wetdem_contact: harmonic for moduli, mean for the others, sum for films). */
struct wetdem_material {
    double density;        /* [kg/m^3] > 0 */
    double youngs_modulus; /* E [Pa] > 0 */
    double poisson_ratio;  /* nu [-], in [-1, 0.5) */
    double restitution;    /* dry coefficient of restitution e_dry [-], in (0, 1] */
    double friction_dry;   /* Coulomb coefficient of dry contact [-] >= 0 */
    double friction_lub;   /* Coulomb coefficient of lubricated contact [-] >= 0 */
    double roughness;      /* mean asperity height sigma [m] >= 0 (Nijssen Eq. 3) */
    double film;           /* liquid film thickness delta_i on this sphere [m] >= 0 */
};

/* The liquid between or around the spheres. */
struct wetdem_fluid {
    double viscosity;       /* mu [Pa s] >= 0 */
    double surface_tension; /* sigma [N/m] >= 0 */
    double density;         /* [kg/m^3] >= 0 (for Reynolds-number checks only) */
};

/* ======================================================================================== */
/* Status and errors                                                                        */
/* ======================================================================================== */

enum wetdem_status {
    WETDEM_OK = 0,
    WETDEM_EVENT = 1,          /* stopped at a terminal event: information, not an error */
    WETDEM_RETRY = 2,          /* internal: the step was too large */
    WETDEM_ERR_NOMEM = -1,     /* out of memory */
    WETDEM_ERR_INVALID = -2,   /* bad argument or parameter value */
    WETDEM_ERR_NOT_FOUND = -3, /* unknown model, integrator, material or parameter name */
    WETDEM_ERR_STEP = -4,      /* the integrator could not reach its tolerance */
    WETDEM_ERR_MAX_STEPS = -5, /* step budget exhausted */
    WETDEM_ERR_CALLBACK = -6,  /* a user callback returned an error */
    WETDEM_ERR_IO = -7,        /* a file could not be read or written */
    WETDEM_ERR_PARSE = -8,     /* a scenario or data file is malformed */
    WETDEM_ERR_NUMERIC = -9,   /* NaN or infinity appeared in the state */
};

/* Name of a status code, e.g. "WETDEM_ERR_INVALID"; "WETDEM_UNKNOWN" for other values. */
WETDEM_API const char* wetdem_status_name(int status);

/* ======================================================================================== */
/* Parameters: named, documented, range-checked                                             */
/* ======================================================================================== */

/* Descriptor of one parameter stored as a double at `offset` in a parameter struct.
 * A parameter with `choices` is an enumeration: the stored double is the index of the
 * chosen word (set it by word with wetdem_sim_set_param_str()). Tables end with {0}. */
struct wetdem_param_desc {
    const char* name;            /* "cutoff_ratio" */
    const char* unit;            /* "m", "Pa s", "-" */
    const char* doc;             /* one sentence */
    size_t offset;               /* offsetof(params struct, field) */
    double default_value;        /* also the index of the default choice */
    double min, max;             /* valid closed range [min, max]; see *_open flags */
    bool min_open, max_open;     /* exclude the bound itself */
    const char* const* choices;  /* NULL-terminated words, or NULL for a number */
};

/* Number of descriptors in a {0}-terminated table. */
WETDEM_API size_t wetdem_param_count(const struct wetdem_param_desc* table);
/* Finds a descriptor by name in a table; NULL if absent. */
WETDEM_API const struct wetdem_param_desc* wetdem_param_find(const struct wetdem_param_desc* table,
                                                             const char* name);
/* Fills a parameter struct with the defaults of its table. */
WETDEM_API void wetdem_param_init_defaults(const struct wetdem_param_desc* table, void* params);
/* Checks `value` against a descriptor. Returns WETDEM_OK or WETDEM_ERR_INVALID and writes a
 * message naming the parameter, the value and the valid range into msg (may be NULL). */
WETDEM_API int wetdem_param_validate(const struct wetdem_param_desc* d, double value, char* msg,
                                     size_t msg_size);
/* Writes the valid range of d as text, e.g. "(0, 1]" or "one of: c, nc". */
WETDEM_API void wetdem_param_range_text(const struct wetdem_param_desc* d, char* buf, size_t n);
/* Index of `word` among d->choices, or -1. */
WETDEM_API int wetdem_param_choice_index(const struct wetdem_param_desc* d, const char* word);
/* The closest of `candidates` (NULL-terminated) to `word` by edit distance, or NULL when
 * nothing is close enough to be a plausible typo. */
WETDEM_API const char* wetdem_param_suggest(const char* word, const char* const* candidates);

/* ======================================================================================== */
/* Materials                                                                                */
/* ======================================================================================== */

/* Fills *m with a built-in preset: "steel1", "steel2", "glass", "delrin" (Nijssen 2023
 * Table 1, the immersed spheres of Yang & Hunt), "punch_steel" (Punch Table 1, dry striker)
 * or "punch_steel_coated" (the same sphere with the 270 um silicone-oil film).
 * Returns WETDEM_OK or WETDEM_ERR_NOT_FOUND. */
WETDEM_API int wetdem_material_preset(const char* name, struct wetdem_material* m);
/* Fills *f with the fluid that goes with a preset: "water" (1e-3 Pa s), "glycerol80"
 * (Yang & Hunt 80 w% glycerol, 0.057 Pa s), "silicone10" (Punch: 10 Pa s, 0.0205 N/m). */
WETDEM_API int wetdem_fluid_preset(const char* name, struct wetdem_fluid* f);
/* NULL-terminated list of material preset names. */
WETDEM_API const char* const* wetdem_material_preset_names(void);
/* Descriptors of struct wetdem_material and struct wetdem_fluid, for docs and validation. */
WETDEM_API const struct wetdem_param_desc* wetdem_material_params(void);
WETDEM_API const struct wetdem_param_desc* wetdem_fluid_params(void);
/* Checks every field of a material; message into msg. WETDEM_OK or WETDEM_ERR_INVALID. */
WETDEM_API int wetdem_material_validate(const struct wetdem_material* m, char* msg, size_t n);
/* Checks every field of a fluid; message into msg. WETDEM_OK or WETDEM_ERR_INVALID. */
WETDEM_API int wetdem_fluid_validate(const struct wetdem_fluid* f, char* msg, size_t n);

/* ======================================================================================== */
/* Pair geometry, pair forces and the model interface                                       */
/* ======================================================================================== */

/* Geometry, kinematics and mixed properties of one interacting pair, computed once per pair
 * (wetdem_contact_from_particles) and read by every model. For a plane wall j, radius_j is
 * INFINITY, m_eff = m_i and r_eff = R_i. */
struct wetdem_contact {
    size_t i, j;               /* particle indices (j: wall index for walls) */
    bool is_wall;              /* j is a plane wall */
    struct wetdem_vec3 normal; /* unit vector from j to i */
    double gap;                /* surface separation h [m]; < 0 overlap */
    double radius_i, radius_j; /* [m] */
    double r_eff;              /* R* [m] */
    double m_eff;              /* m* [kg] */
    double v_n;                /* normal approach speed [m/s], > 0 approaching */
    struct wetdem_vec3 v_t;    /* tangential velocity of i's surface relative to j's at the
                                  contact point [m/s] */
    double dt;                 /* time since the pair's history was last committed [s] */
    /* mixed pair properties */
    double e_star;             /* 1/E* = (1-nu_i^2)/E_i + (1-nu_j^2)/E_j [Pa] */
    double g_star;             /* 1/G* = (2-nu_i)/G_i + (2-nu_j)/G_j [Pa] */
    double restitution;        /* e_dry, mean of the two [-] */
    double friction_dry;       /* mean of the two [-] */
    double friction_lub;       /* mean of the two [-] */
    double roughness;          /* h_sigma = (sigma_i + sigma_j)/2 [m] (Nijssen Eq. 3) */
    double film;               /* delta_ij = delta_i + delta_j [m] */
    double viscosity;          /* fluid mu [Pa s] */
    double surface_tension;    /* fluid sigma [N/m] */
    double h_min;              /* minimum separation from the min-separation model [m] */
};

/* What one model adds for one pair. Forces act on i; j receives the opposite. */
struct wetdem_pair_force {
    double f_normal;             /* along the normal, > 0 repulsive [N] */
    struct wetdem_vec3 f_tan;    /* tangential force on i [N] */
    struct wetdem_vec3 torque_i; /* torque on i about its centre [N m] */
    struct wetdem_vec3 torque_j; /* torque on j about its centre [N m] */
};

enum wetdem_model_kind {
    WETDEM_MODEL_CONTACT = 1,        /* solid contact force (soft) */
    WETDEM_MODEL_FLUID = 2,          /* lubrication, thin-film viscous or capillary force */
    WETDEM_MODEL_MIN_SEPARATION = 3, /* gives h_min for a pair */
    WETDEM_MODEL_IMPULSE = 4,        /* hard-sphere impulse contact */
};

#define WETDEM_MAX_THRESHOLDS 4

/* A named, documented, parameter-checked model (force, minimum separation or impulse). */
struct wetdem_model {
    const char* name;                       /* keyword used by the CLI, scenarios and docs */
    enum wetdem_model_kind kind;
    const char* summary;                    /* one line */
    const char* doc;                        /* a paragraph: physics, validity, units */
    const char* equations;                  /* equation references in the seed papers */
    const struct wetdem_param_desc* params; /* terminated by {0} */
    size_t params_size;                     /* sizeof the model's params struct */
    size_t history_len;                     /* doubles of per-pair state (0 if none) */
    /* Largest gap at which the model acts [m] (force models). */
    double (*range)(const void* params, const struct wetdem_contact* c);
    /* Adds the model's force to *out. history (history_len doubles) holds the committed state
     * on entry and receives the state advanced by c->dt; the caller decides whether to keep
     * it. Returns WETDEM_OK or a negative status. */
    int (*pair)(const void* params, const struct wetdem_contact* c, double* history,
                struct wetdem_pair_force* out);
    /* Minimum separation h_min [m] (min-separation models); may update history. */
    double (*min_separation)(const void* params, const struct wetdem_contact* c,
                             double* history);
    /* Gaps [m] at which the force law changes branch, for event location; returns the count
     * written (<= WETDEM_MAX_THRESHOLDS). Optional. */
    size_t (*thresholds)(const void* params, const struct wetdem_contact* c,
                         const double* history, double* gaps);
};

/* NULL-terminated table of every built-in model. */
WETDEM_API const struct wetdem_model* const* wetdem_model_registry(void);
/* Built-in model by name, or NULL. */
WETDEM_API const struct wetdem_model* wetdem_model_find(const char* name);
/* "contact", "fluid", "min-separation", "impulse". */
WETDEM_API const char* wetdem_model_kind_name(enum wetdem_model_kind kind);

/* Builds the contact of particles a (as i) and b (as j) with their materials and the fluid.
 * h_min and dt are left 0 for the caller to fill. */
WETDEM_API void wetdem_contact_from_particles(struct wetdem_contact* c,
                                              const struct wetdem_particle* a,
                                              const struct wetdem_material* ma,
                                              const struct wetdem_particle* b,
                                              const struct wetdem_material* mb,
                                              const struct wetdem_fluid* fluid);
/* Builds the contact of particle a (as i) with a plane wall through `point` with unit normal
 * `normal` pointing into the domain; mw is the wall's material. */
WETDEM_API void wetdem_contact_with_wall(struct wetdem_contact* c, const struct wetdem_particle* a,
                                         const struct wetdem_material* ma,
                                         struct wetdem_vec3 point, struct wetdem_vec3 normal,
                                         const struct wetdem_material* mw,
                                         const struct wetdem_fluid* fluid);
/* The same contact seen from j: normal, v_t reversed, i and j swapped. */
WETDEM_API struct wetdem_contact wetdem_contact_swapped(const struct wetdem_contact* c);
/* Adds a tangential force on i acting at the contact point: f_tan += ft and the torques
 * torque_i += (-R_i n) x ft, torque_j += (-R_j n) x ft (j receives -ft at +R_j n). */
WETDEM_API void wetdem_pair_force_add_tangential(struct wetdem_pair_force* out,
                                                 const struct wetdem_contact* c,
                                                 struct wetdem_vec3 ft);

/* ======================================================================================== */
/* Hard-sphere impulse contact (Davis 2023 Appendix A, Eqs. A1-A36, in 3-D vector form)      */
/* ======================================================================================== */

/* One body of an impulsive collision. For a wall, mass = INFINITY, radius = INFINITY. */
struct wetdem_impulse_body {
    struct wetdem_vec3 vel;   /* [m/s] */
    struct wetdem_vec3 omega; /* [rad/s] */
    double mass;              /* [kg] */
    double radius;            /* lever arm from centre to contact point [m] */
    double inertia;           /* moment of inertia [kg m^2]; 2/5 m R^2 for a solid sphere */
};

/* Result of wetdem_hard_impulse(). */
struct wetdem_impulse_result {
    double impulse_normal;          /* J_n >= 0 along the normal, on i [N s] */
    struct wetdem_vec3 impulse_tan; /* tangential impulse on i [N s] */
    bool is_sticking;               /* slip arrested (A30-A35) rather than sliding (A8-A11) */
};

/* Applies a hard-sphere collision to bodies i and j in place. normal: unit, from j to i.
 * The normal relative velocity is reversed with e_dry (A1-A3); friction gives a tangential
 * impulse mu_f J_n opposing slip (sliding, A8-A11) unless that exceeds what arrests the slip
 * (A36), in which case slip stops (A33). Returns WETDEM_OK, or WETDEM_ERR_INVALID for
 * non-positive masses/radii, e_dry outside (0, 1] or mu_f < 0. Separating pairs
 * (v_n <= 0) are left unchanged and WETDEM_OK is returned. */
WETDEM_API int wetdem_hard_impulse(struct wetdem_impulse_body* bi, struct wetdem_impulse_body* bj,
                                   struct wetdem_vec3 normal, double restitution, double friction,
                                   struct wetdem_impulse_result* result);

/* ======================================================================================== */
/* Simulation object                                                                        */
/* ======================================================================================== */

struct wetdem_sim;

/* Allocates an empty simulation with default settings. NULL only if out of memory. */
WETDEM_API struct wetdem_sim* wetdem_sim_create(void);
/* Frees the simulation and everything it owns. NULL does nothing. */
WETDEM_API void wetdem_sim_free(struct wetdem_sim* sim);
/* Last detailed error message of this simulation, "" if none. */
WETDEM_API const char* wetdem_sim_errmsg(const struct wetdem_sim* sim);

/* Appends a material (copied, validated). Returns its index >= 0, or a negative status. */
WETDEM_API int wetdem_sim_add_material(struct wetdem_sim* sim, const struct wetdem_material* m);
/* Appends a material preset by name; returns its index or a negative status. */
WETDEM_API int wetdem_sim_add_material_preset(struct wetdem_sim* sim, const char* name);
/* Borrowed pointer to material k, NULL if out of range. */
WETDEM_API const struct wetdem_material* wetdem_sim_material(const struct wetdem_sim* sim, int k);
/* Number of materials. */
WETDEM_API int wetdem_sim_n_materials(const struct wetdem_sim* sim);
/* Sets the fluid (validated). */
WETDEM_API int wetdem_sim_set_fluid(struct wetdem_sim* sim, const struct wetdem_fluid* f);
/* The fluid. */
WETDEM_API struct wetdem_fluid wetdem_sim_fluid(const struct wetdem_sim* sim);

/* Appends a copy of p (validated: finite, radius > 0, known material). A mass of 0 is filled
 * from the material density. Returns WETDEM_OK or a negative status. */
WETDEM_API int wetdem_sim_add_particle(struct wetdem_sim* sim, struct wetdem_particle p);
/* Borrowed view of the particles, valid until the next add. *n receives the count. */
WETDEM_API struct wetdem_particle* wetdem_sim_particles(struct wetdem_sim* sim, size_t* n);
/* Number of particles. */
WETDEM_API size_t wetdem_sim_n_particles(const struct wetdem_sim* sim);
/* Adds a plane wall through `point` with unit `normal` into the domain, of material k. */
WETDEM_API int wetdem_sim_add_wall(struct wetdem_sim* sim, struct wetdem_vec3 point,
                                   struct wetdem_vec3 normal, int material);
/* Number of walls. */
WETDEM_API size_t wetdem_sim_n_walls(const struct wetdem_sim* sim);

/* Enables a built-in model by name for every pair (force models add up; one min-separation
 * model; one impulse model). Enabling a min-separation model replaces the previous one.
 * Returns WETDEM_OK, WETDEM_ERR_NOT_FOUND (message with a suggestion) or WETDEM_ERR_INVALID. */
WETDEM_API int wetdem_sim_enable_model(struct wetdem_sim* sim, const char* name);
/* Attaches a custom force model to this simulation only; params (model->params_size bytes)
 * are copied. */
WETDEM_API int wetdem_sim_add_model(struct wetdem_sim* sim, const struct wetdem_model* model,
                                    const void* params);
/* Disables every force model and resets the min-separation model to "fixed". */
WETDEM_API void wetdem_sim_clear_models(struct wetdem_sim* sim);
/* Number of enabled force models, and the k-th. */
WETDEM_API size_t wetdem_sim_n_models(const struct wetdem_sim* sim);
WETDEM_API const struct wetdem_model* wetdem_sim_model(const struct wetdem_sim* sim, size_t k);
/* The min-separation model in use. */
WETDEM_API const struct wetdem_model* wetdem_sim_min_separation_model(const struct wetdem_sim* s);

/* Sets a parameter by dotted name: "<model>.<param>" for an enabled model or the
 * min-separation model, "fluid.<field>", "sim.<setting>". Checks range and finiteness.
 * Returns WETDEM_OK, WETDEM_ERR_NOT_FOUND ("did you mean ...") or WETDEM_ERR_INVALID. */
WETDEM_API int wetdem_sim_set_param(struct wetdem_sim* sim, const char* name, double value);
/* Sets an enumerated parameter by word, e.g. ("db.below_hmin", "nc"); numbers are accepted
 * as text too. */
WETDEM_API int wetdem_sim_set_param_str(struct wetdem_sim* sim, const char* name,
                                        const char* value);
/* Reads a parameter by dotted name into *value. */
WETDEM_API int wetdem_sim_param(const struct wetdem_sim* sim, const char* name, double* value);

/* Evaluates the sum of the enabled force models for particles i and j (j may equal
 * (size_t)-1 - w to address wall w) with the given per-pair history (may be NULL: fresh
 * history), at the current state. Writes the contact used into *c if non-NULL. */
WETDEM_API int wetdem_sim_pair_force(struct wetdem_sim* sim, size_t i, size_t j,
                                     struct wetdem_contact* c, struct wetdem_pair_force* out);

/* ======================================================================================== */
/* Soft engine: integration, events, analysis (see docs/engines.md)                         */
/* ======================================================================================== */

/* Integrators are chosen by name: "verlet" (velocity Verlet, fixed step dt = dt_fraction x
 * the Hertz contact time of the fastest pair, Nijssen 2023 Sec. 3) or "cvode" (SUNDIALS CVODE,
 * adaptive, with every branch boundary of the force laws located as an event). Their
 * parameters are set by dotted name: "verlet.dt_fraction", "verlet.dt", "cvode.rtol", ... */
WETDEM_API int wetdem_sim_set_integrator(struct wetdem_sim* sim, const char* name);
/* Name of the integrator in use ("verlet" by default). */
WETDEM_API const char* wetdem_sim_integrator_name(const struct wetdem_sim* sim);
/* NULL-terminated list of integrator names. */
WETDEM_API const char* const* wetdem_integrator_names(void);

/* Advances the simulation to time t_end [s]. Returns WETDEM_OK at t_end, WETDEM_EVENT when a
 * stop condition fired (sim.stop_on_separation), or a negative status (message in errmsg). */
WETDEM_API int wetdem_sim_integrate(struct wetdem_sim* sim, double t_end);
/* Current simulated time [s]. */
WETDEM_API double wetdem_sim_time(const struct wetdem_sim* sim);

/* Work counters since the simulation was created or reset (CVODE GetNum* style). */
struct wetdem_stats {
    unsigned long long steps;          /* accepted steps */
    unsigned long long rejected_steps; /* failed or rejected step attempts */
    unsigned long long force_evals;    /* evaluations of all forces on all particles (RHS) */
    unsigned long long pair_evals;     /* evaluations of one pair's models */
    unsigned long long root_evals;     /* evaluations of the event functions */
    unsigned long long events;         /* events located */
};
WETDEM_API struct wetdem_stats wetdem_sim_stats(const struct wetdem_sim* sim);

/* Located crossings of a pair's gap through a branch boundary of the force law. */
enum wetdem_event_kind {
    WETDEM_EVENT_INTERACTION_START = 1, /* gap fell below the largest model range */
    WETDEM_EVENT_HMIN_REACHED = 2,      /* gap fell below h_min */
    WETDEM_EVENT_CONTACT_START = 3,     /* gap fell below 0: solid overlap begins */
    WETDEM_EVENT_CONTACT_END = 4,       /* gap rose above 0 */
    WETDEM_EVENT_HMIN_LEFT = 5,         /* gap rose above h_min */
    WETDEM_EVENT_INTERACTION_END = 6,   /* gap rose above the largest model range */
    WETDEM_EVENT_HARD_CONTACT = 7,      /* hard-sphere impulse (pairwise engine) */
    WETDEM_EVENT_PARTNER_CHANGE = 8,    /* tracked pairs changed (pairwise engine) */
    WETDEM_EVENT_BRANCH = 9,            /* gap crossed another branch boundary that a model
                                           lists in thresholds() (either direction) */
};
struct wetdem_event_record {
    double time;                /* [s] */
    enum wetdem_event_kind kind;
    size_t i, j;                /* pair (j: wall index when is_wall) */
    bool is_wall;
    double gap;                 /* gap at the event [m] */
    double v_n;                 /* normal approach speed at the event [m/s] */
};
/* Name of an event kind, e.g. "contact_start". */
WETDEM_API const char* wetdem_event_kind_name(enum wetdem_event_kind kind);
/* Borrowed view of the event log, valid until the next integrate/reset. */
WETDEM_API const struct wetdem_event_record* wetdem_sim_events(const struct wetdem_sim* sim,
                                                               size_t* n);

/* Called every `interval` seconds of simulated time (and at t = 0 and at the end) with the
 * current state; a non-zero return stops the integration with WETDEM_ERR_CALLBACK. */
typedef int (*wetdem_observer_fn)(const struct wetdem_sim* sim, void* ctx);
WETDEM_API void wetdem_sim_set_observer(struct wetdem_sim* sim, double interval,
                                        wetdem_observer_fn fn, void* ctx);
/* Read-only particle view for observers. */
WETDEM_API const struct wetdem_particle* wetdem_sim_particles_const(const struct wetdem_sim* sim,
                                                                    size_t* n);

/* ---- two-body collision analysis (SPEC §4) ---- */

enum wetdem_outcome {
    WETDEM_OUTCOME_STICK = 0,                 /* no separation by t_end */
    WETDEM_OUTCOME_STICK_ROTATE_SEPARATE = 1, /* separated after rotating as a doublet */
    WETDEM_OUTCOME_BOUNCE = 2,                /* separated promptly (contact-bounce) */
};
/* "stick", "stick-rotate-separate", "bounce". */
WETDEM_API const char* wetdem_outcome_name(enum wetdem_outcome outcome);

/* A binary collision: sphere i (the striker) moves towards a target j at rest (a sphere, or a
 * plane wall). Materials, fluid, models and integrator come from the simulation. */
struct wetdem_collision_spec {
    int material_i, material_j; /* material indices (j: the target's or the wall's) */
    double radius_i, radius_j;  /* [m]; radius_j ignored for a wall */
    bool target_is_wall;        /* j is a plane wall */
    bool target_is_fixed;       /* target sphere held in place */
    double speed;               /* impact speed of i [m/s]; 0: derived from stokes */
    double stokes;              /* normal Stokes number St_n = m* v_n0/(6 pi mu R*^2), used
                                   when speed == 0 */
    double angle;               /* impact angle [rad]: between the velocity of i and the line
                                   of centres at first interaction; 0 = head-on */
    struct wetdem_vec3 omega_i; /* initial spin of i [rad/s] */
    double initial_gap;         /* gap at t = 0 [m]; <= 0: just outside the interaction range */
    double t_end;               /* longest simulated time [s] */
    double observe_time;        /* > 0: also report e_n at this time (Punch Fig. 9 window) */
    double rebound_gap_factor;  /* separation is declared when the gap exceeds this multiple
                                   of the interaction range (>= 1; 0 means 1) */
};

struct wetdem_collision_result {
    double stokes_n;            /* normal Stokes number of the impact [-] */
    double speed_n0;            /* normal approach speed at first interaction [m/s] */
    double e;                   /* Nijssen: |dv_1|/|dv_0| of the relative velocity [-] */
    double e_n;                 /* normal restitution -v_f.n_f / v_0.n_0 (Punch Eq. 3) [-] */
    double e_t;                 /* tangential restitution of the contact-point velocity [-] */
    double e_n_observed;        /* e_n evaluated at observe_time (NAN if not requested) */
    double angle_in, angle_out; /* impact and rebound angles to the normal [rad] */
    struct wetdem_vec3 omega_i, omega_j; /* final spins [rad/s] */
    double contact_duration;    /* total time with gap < 0 [s] */
    double interaction_duration;/* time from first interaction to separation [s] */
    double min_gap;             /* smallest gap reached [m] */
    bool solid_contact;         /* gap reached 0 */
    bool hmin_reached;          /* gap reached h_min */
    bool separated;             /* left the interaction range by t_end */
    double rotation_angle;      /* angle the line of centres turned during interaction [rad] */
    enum wetdem_outcome outcome;
    struct wetdem_stats stats;
};

/* Sets up and runs one binary collision on `sim` (its particles are replaced; its materials,
 * fluid, models, integrator and parameters are used). Returns WETDEM_OK or a negative status.
 * The event log of the run stays available through wetdem_sim_events(). */
WETDEM_API int wetdem_collision_run(struct wetdem_sim* sim, const struct wetdem_collision_spec* spec,
                                    struct wetdem_collision_result* result);
/* Removes all particles and walls, the event log, pair histories and statistics, and sets
 * the time to 0; materials, fluid, models and parameters are kept. */
WETDEM_API void wetdem_sim_reset(struct wetdem_sim* sim);
/* Deep copy (materials, fluid, models, parameters, integrator, particles; not the observer).
 * NULL if out of memory. For running independent collisions in parallel. */
WETDEM_API struct wetdem_sim* wetdem_sim_clone(const struct wetdem_sim* sim);

/* ======================================================================================== */
/* Pairwise engine (Davis 2023)                                                             */
/* ======================================================================================== */

/* ---- pairwise engine section ---- */

/* ======================================================================================== */
/* Experiment tracking and fitting (Punch 2023 Sec. 3.2)                                    */
/* ======================================================================================== */

/* ---- tracking section ---- */

/* Tracked dots of the spheres of one Stokes-cradle video (opaque). Each sphere carries three
 * painted dots: dot 1 on the vertical axis through the centre (in line with the suspension
 * string), dots 2 and 3 beside it (Punch 2023 Sec. 3.1-3.2). docs/tracking.md. */
struct wetdem_track;

/* Settings of wetdem_track_analyse(); wetdem_track_options_init() gives the defaults. */
struct wetdem_track_options {
    double fps;          /* frame rate [1/s] > 0 (Punch: 5000) */
    double pixel_size;   /* image resolution [m/pixel] > 0 (Punch: 175e-6) */
    bool y_down;         /* the y pixel axis points down (image rows): y is negated on input so
                            that (x, y) is right-handed and omega > 0 is counter-clockwise on
                            screen (default false) */
    int window;          /* Savitzky-Golay window [frames], odd, > order (7); 1: no smoothing */
    int order;           /* Savitzky-Golay polynomial order, >= 0, < window (2) */
    double threshold;    /* collision: striker velocity change [m/s] > 0 (0.05) */
    int offset;          /* frames before/after the collision frame where the velocities are
                            taken (5), >= 1 */
    int fit_frames;      /* frame intervals in each straight-line fit, >= 3; 0: all (0) */
    int striker;         /* sphere id of the striker; -1: the faster sphere at the start (-1) */
    double radius;       /* sphere radius [m] for St_n; 0: not given (no St_n) */
    double mass;         /* sphere mass [kg] for St_n; 0: not given */
    double viscosity;    /* film viscosity [Pa s] for St_n; 0: not given */
};

/* Velocity of one sphere over the frame interval frame -> frame + 1 (Punch Eq. 23). */
struct wetdem_track_sample {
    long frame;                        /* first frame of the interval */
    double time;                       /* interval midpoint (frame + 1/2)/fps [s] */
    double vx_raw, vy_raw, omega_raw;  /* from the unsmoothed dots [m/s], [rad/s] */
    double vx, vy, omega;              /* from the Savitzky-Golay smoothed dots */
    double residual;                   /* rms residual of Eq. 23 on the smoothed dots [m] */
};

/* Velocities and dot-1 position of one sphere at one frame (straight-line fit values). */
struct wetdem_track_state {
    double vx, vy;  /* [m/s] */
    double omega;   /* spin about the camera axis, counter-clockwise in (x, y) [rad/s] */
    double x, y;    /* smoothed position of dot 1 (the centre) [m] */
};

/* The collision found in a two-sphere track. */
struct wetdem_track_summary {
    size_t n_spheres;                /* 1 or 2; the fields below need 2 */
    bool has_collision;
    int striker_id, target_id;       /* sphere ids as in the input */
    long collision_frame;            /* last frame before the striker's velocity changes */
    double collision_time;           /* collision_frame / fps [s] */
    struct wetdem_track_state striker_before, striker_after; /* at collision_frame -/+ offset */
    struct wetdem_track_state target_before, target_after;
    double angle_centres;            /* Eq. 16: atan of dy/dx of the centres at the collision
                                        frame [rad], in (-pi/2, pi/2] */
    double impact_angle;             /* angle between the relative velocity before and the
                                        line of centres at the collision frame [rad] */
    double speed_n0, speed_nf;       /* normal relative speed before (approach > 0) and after
                                        (separation > 0) [m/s] */
    double e_n;                      /* Eq. 3: speed_nf / speed_n0 [-] */
    double stokes_n;                 /* Eq. 2 with m* = m/2, R* = R/2; NAN without options */
};

/* Allocates an empty track. NULL only if out of memory. */
WETDEM_API struct wetdem_track* wetdem_track_create(void);
/* Frees a track and its results. NULL does nothing. */
WETDEM_API void wetdem_track_free(struct wetdem_track* track);
/* Last detailed error message of this track ("" if none). */
WETDEM_API const char* wetdem_track_errmsg(const struct wetdem_track* track);
/* Appends one frame of sphere `sphere_id` (>= 0; at most two spheres): xy = x1,y1,x2,y2,x3,y3
 * [pixel]. Frames of a sphere must follow one another without gaps. Returns WETDEM_OK,
 * WETDEM_ERR_INVALID (NaN, gap, non-increasing frame, third sphere) or WETDEM_ERR_NOMEM. */
WETDEM_API int wetdem_track_add_frame(struct wetdem_track* track, int sphere_id, long frame,
                                      const double xy[6]);
/* Reads a CSV of rows frame,sphere,x1,y1,x2,y2,x3,y3 (optional header, '#' comments) and
 * appends them. Returns WETDEM_OK, WETDEM_ERR_IO, WETDEM_ERR_PARSE (message "FILE:LINE: ...")
 * or WETDEM_ERR_NOMEM. */
WETDEM_API int wetdem_track_read_csv(struct wetdem_track* track, const char* path);
/* Fills *opt with the defaults (fps and pixel_size 0: the caller must set them). */
WETDEM_API void wetdem_track_options_init(struct wetdem_track_options* opt);
/* Computes the per-frame velocities of every sphere and, with two spheres, the collision
 * summary (Punch Sec. 3.2). Returns WETDEM_OK, WETDEM_ERR_INVALID (bad options, too few
 * frames, spheres over different frames, no collision found; message in errmsg) or
 * WETDEM_ERR_NOMEM. */
WETDEM_API int wetdem_track_analyse(struct wetdem_track* track,
                                    const struct wetdem_track_options* opt,
                                    struct wetdem_track_summary* summary);
/* Number of spheres, and the id of the k-th (in order of first appearance; -1 if k is out of
 * range). */
WETDEM_API size_t wetdem_track_n_spheres(const struct wetdem_track* track);
WETDEM_API int wetdem_track_sphere_id(const struct wetdem_track* track, size_t k);
/* Borrowed per-interval velocities of the k-th sphere after wetdem_track_analyse(); *n gets
 * the count (frames - 1). Valid until the track is changed or freed; NULL before analysis. */
WETDEM_API const struct wetdem_track_sample* wetdem_track_samples(const struct wetdem_track* t,
                                                                  size_t k, size_t* n);

/* ---- model calibration: nonlinear least squares (src/fit.c, docs/calibration.md) ---- */

#define WETDEM_FIT_MAX_PARAMS 8

/* Predictions of a model: fills predicted[0..n_data) for parameter values params[0..n_params)
 * (in their own units). Returns WETDEM_OK, or a negative status with a message in msg. */
typedef int (*wetdem_fit_model_fn)(const double* params, double* predicted, char* msg,
                                   size_t msg_size, void* ctx);

/* A least-squares problem: minimise sum_i ((predicted_i - observed_i)/scale_i)^2. */
struct wetdem_fit_problem {
    size_t n_params;           /* 1..WETDEM_FIT_MAX_PARAMS */
    const char* const* names;  /* parameter names for messages (may be NULL) */
    const double* initial;     /* initial values [n_params] */
    const bool* is_log;        /* fit ln(p) (p stays > 0) per parameter; NULL: when initial > 0 */
    size_t n_data;             /* > n_params (the residual variance needs a degree of freedom) */
    const double* observed;    /* [n_data] */
    const double* scale;       /* [n_data] divisor of each residual (> 0), NULL: all 1 */
    wetdem_fit_model_fn model;
    void* ctx;
};

struct wetdem_fit_options {
    int max_iter;    /* trust-region iterations (50) */
    double xtol;     /* step tolerance, relative in the fitted variables (1e-6) */
    double gtol;     /* gradient tolerance (1e-8) */
    double ftol;     /* cost-reduction tolerance (1e-10) */
    double fd_step;  /* central-difference step of the Jacobian in the fitted variable:
                        relative change for log parameters, absolute x max(|p|, 1) otherwise
                        (1e-2: larger than the integration noise of simulated predictions) */
};

struct wetdem_fit_result {
    double values[WETDEM_FIT_MAX_PARAMS];     /* best-fit parameters */
    double std_errors[WETDEM_FIT_MAX_PARAMS]; /* standard errors: sqrt(diag((J^T J)^-1)) s in
                                                 the fitted variable, s^2 = cost/dof, mapped to
                                                 p by dp = p d(ln p) for log parameters */
    double correlation[WETDEM_FIT_MAX_PARAMS][WETDEM_FIT_MAX_PARAMS]; /* of the estimates */
    double cost;          /* sum of squared scaled residuals at the solution */
    double residual_std;  /* s = sqrt(cost/dof), in units of the scale */
    size_t dof;           /* n_data - n_params */
    size_t iterations;
    size_t model_evals;   /* calls of the model function */
    int converged_by;     /* 1 small step (xtol), 2 small gradient (gtol), 3 small cost change */
};

/* Fills *opt with the defaults above. */
WETDEM_API void wetdem_fit_options_init(struct wetdem_fit_options* opt);
/* Solves the problem with the GSL trust-region (Levenberg-Marquardt) solver and a
 * central-difference Jacobian. predicted (may be NULL) receives the predictions at the
 * solution [n_data]. Returns WETDEM_OK, WETDEM_ERR_INVALID (bad problem or options),
 * WETDEM_ERR_CALLBACK (the model failed), WETDEM_ERR_MAX_STEPS (not converged; *result holds
 * the last iterate) or WETDEM_ERR_NOMEM; msg (may be NULL) receives a message. */
WETDEM_API int wetdem_fit_run(const struct wetdem_fit_problem* problem,
                              const struct wetdem_fit_options* opt,
                              struct wetdem_fit_result* result, double* predicted, char* msg,
                              size_t msg_size);

/* ======================================================================================== */
/* ABI checks for bindings                                                                  */
/* ======================================================================================== */

/* sizeof of the public value types, for bindings that mirror them. */
WETDEM_API size_t wetdem_abi_sizeof(const char* type_name);

#ifdef __cplusplus
}
#endif

#endif /* WETDEM_H */
