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
 * wetdem_sim_errmsg() returns. Pointer arguments are not NULL unless an entry says what NULL
 * means; the functions that take a name, a material, a fluid, a model or a path also refuse a
 * NULL one (WETDEM_ERR_INVALID; a lookup that returns a pointer, an index or a size gives NULL,
 * -1 or 0, as for a name it does not know).
 *
 * Threads (docs/concepts.md): every object (struct wetdem_sim, wetdem_pairwise, wetdem_track)
 * holds all of its state, and the library's tables are read-only, so distinct objects may be
 * used at the same time from different threads (pthreads, OpenMP), with results bit-identical
 * to using them one after the other. One object is used by one thread at a time (no locks:
 * calls on it must not overlap, reading ones included, as a failing query stores its message
 * in the object), except that several threads may wetdem_sim_clone() one simulation that none
 * changes meanwhile; callbacks run in the calling thread. The one process-wide
 * setting the library changes is GSL's error handler, switched off from the start of the first
 * running fit to the end of the last (wetdem_fit_run), and for the moment a collision analysis
 * allocates its quadrature table. A many-particle run's OpenMP loops use
 * the calling thread's omp_get_max_threads(): when several threads run at once, lower it in
 * each (omp_set_num_threads; the results do not depend on it) so as not to oversubscribe cores.
 *
 * Locale (docs/concepts.md): numbers in the library's files and in the text it reads have a
 * decimal point whatever LC_NUMERIC the host set; a call that reads or writes them switches
 * its own thread to the C locale (uselocale) until it returns, and not the process's.
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
    bool is_fixed;            /* held in place (infinite mass), e.g. a target on a support;
                               * its velocity and spin must then be zero */
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
    WETDEM_EVENT = 1,              /* stopped at a terminal event: information, not an error */
    WETDEM_RETRY = 2,              /* internal: the step was too large */
    WETDEM_ERR_NOMEM = -1,         /* out of memory */
    WETDEM_ERR_INVALID = -2,       /* bad argument or parameter value */
    WETDEM_ERR_NOT_FOUND = -3,     /* unknown model, integrator, material or parameter name */
    WETDEM_ERR_STEP = -4,          /* the integrator could not reach its tolerance */
    WETDEM_ERR_MAX_STEPS = -5,     /* step budget exhausted */
    WETDEM_ERR_CALLBACK = -6,      /* a user callback returned an error */
    WETDEM_ERR_IO = -7,            /* a file could not be read or written */
    WETDEM_ERR_PARSE = -8,         /* a scenario or data file is malformed */
    WETDEM_ERR_NUMERIC = -9,       /* NaN or infinity appeared in the state */
    WETDEM_ERR_UNDETERMINED = -10, /* a fit's data do not determine a parameter */
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
    const char* name;           /* "cutoff_ratio" */
    const char* unit;           /* "m", "Pa s", "-" */
    const char* doc;            /* one sentence */
    size_t offset;              /* offsetof(params struct, field) */
    double default_value;       /* also the index of the default choice */
    double min, max;            /* valid closed range [min, max]; see *_open flags */
    bool min_open, max_open;    /* exclude the bound itself */
    const char* const* choices; /* NULL-terminated words, or NULL for a number */
    bool integer;               /* a count or an order: whole numbers only */
};

/* Number of descriptors in a {0}-terminated table. */
WETDEM_API size_t wetdem_param_count(const struct wetdem_param_desc* table);
/* Finds a descriptor by name in a table; NULL if absent. */
WETDEM_API const struct wetdem_param_desc* wetdem_param_find(const struct wetdem_param_desc* table,
                                                             const char* name);
/* Fills a parameter struct with the defaults of its table. */
WETDEM_API void wetdem_param_init_defaults(const struct wetdem_param_desc* table, void* params);
/* Checks `value` against a descriptor. Returns WETDEM_OK or WETDEM_ERR_INVALID and writes a
 * message naming the parameter, the value and the valid range into msg (may be NULL). A NULL
 * d (what wetdem_param_find answers for an unknown name) is WETDEM_ERR_INVALID with a message
 * saying so. */
WETDEM_API int wetdem_param_validate(const struct wetdem_param_desc* d, double value, char* msg,
                                     size_t msg_size);
/* The two writers of text below follow snprintf: at most n bytes, NUL included, go to buf
 * (the text cut short when it is longer; nothing when n is 0, and buf may then be NULL), and
 * they return the length of the whole text without its NUL, so a return >= n means it was cut
 * short and says how large a buffer it needs (plus 1). */
/* Writes the valid range of d as text, e.g. "(0, 1]" or "one of: c, nc"; d NULL: "". */
WETDEM_API size_t wetdem_param_range_text(const struct wetdem_param_desc* d, char* buf, size_t n);
/* value with the fewest significant digits, at least min_digits (1..17; others are taken as
 * the nearer end), that read back as value (17 if none do, as for NaN); e.g. 1.000000000001
 * at 6, not 1; with a decimal point in any locale. The digits do not depend on n: a short buf
 * receives the start of that text. */
WETDEM_API size_t wetdem_param_format_value(double value, int min_digits, char* buf, size_t n);
/* Index of `word` among d->choices, or -1. */
WETDEM_API int wetdem_param_choice_index(const struct wetdem_param_desc* d, const char* word);
/* The closest of `candidates` (NULL-terminated) to `word` by edit distance (insertions,
 * deletions, substitutions and swaps of adjacent letters count 1; ties go to the first), or
 * NULL when nothing is close enough to be a plausible typo. */
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
 * (Yang & Hunt 80 w% glycerol, 0.060 Pa s), "silicone10" (Punch: 10 Pa s, 0.0205 N/m).
 * Returns WETDEM_OK or WETDEM_ERR_NOT_FOUND. */
WETDEM_API int wetdem_fluid_preset(const char* name, struct wetdem_fluid* f);
/* NULL-terminated list of material preset names. */
WETDEM_API const char* const* wetdem_material_preset_names(void);
/* Descriptors of struct wetdem_material and struct wetdem_fluid, for docs and validation. */
WETDEM_API const struct wetdem_param_desc* wetdem_material_params(void);
WETDEM_API const struct wetdem_param_desc* wetdem_fluid_params(void);
/* The mass density (4/3) pi R^3 [kg] of a solid sphere of material m and radius R [m], as the
 * library fills in a particle's mass of 0: callers deriving m* or St_n get the library's bits.
 * NaN for a NULL m. */
WETDEM_API double wetdem_material_sphere_mass(const struct wetdem_material* m, double radius);
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
    /* Added to v_t in the tangential spring's increment over dt [m/s], so that the spring
     * advances with the slip over dt (docs/engines.md): in the two-body CVODE engine the
     * increment of the integral of v_t that it carries as state, over dt and in the tangent
     * plane, less v_t (under its error control); in the fixed-step engines (verlet, the
     * many-particle mode) the slip at the half-step velocities less v_t (midpoint rule).
     * wetdem_contact_from_particles sets it to 0 (the spring advances by v_t dt); a contact
     * filled in by hand must too. */
    struct wetdem_vec3 dv_t_spring;
    /* mixed pair properties */
    double e_star;          /* 1/E* = (1-nu_i^2)/E_i + (1-nu_j^2)/E_j [Pa] */
    double g_star;          /* 1/G* = (2-nu_i)/G_i + (2-nu_j)/G_j [Pa] */
    double restitution;     /* e_dry, mean of the two [-] */
    double friction_dry;    /* mean of the two [-] */
    double friction_lub;    /* mean of the two [-] */
    double roughness;       /* h_sigma = (sigma_i + sigma_j)/2 [m] (Nijssen Eq. 3) */
    double film;            /* delta_ij = delta_i + delta_j [m] */
    double viscosity;       /* fluid mu [Pa s] */
    double surface_tension; /* fluid sigma [N/m] */
    double h_min;           /* minimum separation from the min-separation model [m] */
    /* Normal stiffness k [N/m] of the enabled linear solid-contact law (its linear_stiffness
     * hook: hooke's k), filled in by the engines as h_min is, so that the tangential spring
     * (mindlin) follows the normal law beside it without reading that model's force; 0 when
     * the normal law is Hertzian or absent (wetdem_contact_from_particles sets 0). */
    double linear_stiffness;
};

/* What one model adds for one pair. Forces act on i; j receives the opposite. */
struct wetdem_pair_force {
    double f_normal;             /* along the normal, > 0 repulsive [N] */
    struct wetdem_vec3 f_tan;    /* tangential force on i [N] */
    struct wetdem_vec3 torque_i; /* torque on i about its centre [N m] */
    struct wetdem_vec3 torque_j; /* torque on j about its centre [N m] */
    /* A tangential history spring in contact (mindlin, nijssen): |F_t| before the Coulomb cap
     * minus the cap mu F_lim [N], > 0 sliding, <= 0 sticking; 0 where no spring acts. The
     * adaptive integrator locates the stick-slip transitions with it (docs/engines.md). */
    double slip;
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
    const char* name; /* keyword used by the CLI, scenarios and docs */
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
    double (*min_separation)(const void* params, const struct wetdem_contact* c, double* history);
    /* Gaps [m] at which the force law changes branch, for event location; returns the count
     * written (<= WETDEM_MAX_THRESHOLDS). Optional. */
    size_t (*thresholds)(const void* params, const struct wetdem_contact* c, const double* history,
                         double* gaps);
    /* Duration of an impact [s] at approach speed c->v_n > 0 (models with a solid contact;
     * optional). The explicit engines derive their step from the shortest. */
    double (*contact_time)(const void* params, const struct wetdem_contact* c);
    /* Constant normal stiffness dF_n/d(delta) [N/m] of a linear solid-contact law (hooke's k),
     * which the engines pass to every model as c->linear_stiffness. Optional: NULL for a law
     * that is not linear (hertz). */
    double (*linear_stiffness)(const void* params, const struct wetdem_contact* c);
    /* Shortest relaxation time m / c_d [s] of the motion the model damps viscously, at the
     * smallest gap it acts at (c->h_min and c->linear_stiffness filled in, c->v_n the approach
     * speed): c_d = dF/dv, m = m* for normal and (2/7) m* for tangential motion (the spins
     * take part); INFINITY where the model damps nothing, 0 where c_d has no bound. Optional.
     * The many-particle engine keeps its step below a quarter of the shortest (docs/many.md,
     * Time step). */
    double (*relaxation_time)(const void* params, const struct wetdem_contact* c);
    /* The next three read the pair's state at its latest evaluation: c as pair() received it
     * (c->h_min and c->dt not filled in), history (history_len doubles, read only) as pair()
     * left it. All optional; the many-particle engine reports with them (docs/many.md). */
    /* Energy stored in the conservative part of the model's solid-contact force [J]: the
     * work that part does as the pair separates from c->gap to where it vanishes, h_min and
     * every other branch gap held as they are now. NULL: the model stores none. */
    double (*elastic_energy)(const void* params, const struct wetdem_contact* c,
                             const double* history);
    /* Whether the model exerts a solid-contact force at c. NULL: it has no solid contact. */
    bool (*is_in_contact)(const void* params, const struct wetdem_contact* c,
                          const double* history);
    /* Whether the model's liquid bridge joins the pair at c. NULL: it has no bridge. */
    bool (*is_bridged)(const void* params, const struct wetdem_contact* c, const double* history);
    /* Min-separation models whose history is a record of the encounter (ehd, max, glass): the
     * largest gap [m] up to which the record is kept. Beyond the force range but within this
     * gap the engines still evaluate min_separation() on the pair's history (which updates the
     * record) and give the force models a fresh history; beyond both, the whole history is
     * fresh. Optional: without it the record ends with the force range. */
    double (*record_range)(const void* params, const struct wetdem_contact* c);
};

/* NULL-terminated table of every built-in model. */
WETDEM_API const struct wetdem_model* const* wetdem_model_registry(void);
/* Built-in model by name, or NULL. */
WETDEM_API const struct wetdem_model* wetdem_model_find(const char* name);
/* "contact", "fluid", "min-separation", "impulse". */
WETDEM_API const char* wetdem_model_kind_name(enum wetdem_model_kind kind);

/* Builds the contact of particles a (as i) and b (as j) with their materials and the fluid
 * (NULL: none, viscosity and surface tension 0). h_min, linear_stiffness and dt are left 0
 * for the caller to fill. */
WETDEM_API void
wetdem_contact_from_particles(struct wetdem_contact* c, const struct wetdem_particle* a,
                              const struct wetdem_material* ma, const struct wetdem_particle* b,
                              const struct wetdem_material* mb, const struct wetdem_fluid* fluid);
/* Builds the contact of particle a (as i) with a plane wall through `point` with unit normal
 * `normal` pointing into the domain; mw is the wall's material. */
WETDEM_API void wetdem_contact_with_wall(struct wetdem_contact* c, const struct wetdem_particle* a,
                                         const struct wetdem_material* ma, struct wetdem_vec3 point,
                                         struct wetdem_vec3 normal,
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
 * (A36), in which case slip stops (A33). Returns WETDEM_OK; WETDEM_ERR_INVALID for
 * non-finite velocities, non-positive masses/radii/inertias, a movable body whose 1/m or
 * R^2/I overflows, a normal that is not unit, e_dry outside (0, 1] or mu_f not in [0, inf);
 * or WETDEM_ERR_NUMERIC when the impulse or the velocities after it overflow. The bodies are
 * unchanged on an error. Separating pairs (v_n <= 0) are left unchanged and WETDEM_OK is
 * returned. */
WETDEM_API int wetdem_hard_impulse(struct wetdem_impulse_body* bi, struct wetdem_impulse_body* bj,
                                   struct wetdem_vec3 normal, double restitution, double friction,
                                   struct wetdem_impulse_result* result);

/* ======================================================================================== */
/* Simulation object                                                                        */
/* ======================================================================================== */

struct wetdem_sim;

/* Allocates an empty simulation: no materials, particles, walls or force models; the fluid
 * water (wetdem_fluid_preset "water"), the min-separation model "fixed", the integrator
 * "verlet" and the settings of wetdem_sim_settings_params(), each with its defaults. NULL only
 * if out of memory. */
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
/* Borrowed view of the particles, valid until the next add. *n receives the count. A program
 * may edit them through it between calls (docs/many.md, Limits); the calls that read them then
 * check them as wetdem_sim_add_particle does (a mass of 0 is not filled in here): a particle it
 * would refuse makes wetdem_sim_integrate, wetdem_sim_pair_force and the reports of a started
 * many-particle run (statistics, energy budget, CSV row, VTK frames and links, checkpoint)
 * return WETDEM_ERR_INVALID with a message naming it. */
WETDEM_API struct wetdem_particle* wetdem_sim_particles(struct wetdem_sim* sim, size_t* n);
/* Number of particles. */
WETDEM_API size_t wetdem_sim_n_particles(const struct wetdem_sim* sim);
/* Adds a plane wall through `point` with `normal` into the domain, of material `material`.
 * The normal is normalised: any finite, non-zero vector (of any length: 1e-200 or 1e200 as
 * well) gives its direction; zero or non-finite ones are WETDEM_ERR_INVALID. In the
 * many-particle mode a wall must be parallel to every periodic axis (|normal| component along
 * it <= 1e-12): wetdem_sim_integrate refuses the run otherwise (WETDEM_ERR_INVALID). A wall
 * added between calls of a many-particle run acts from the next call on, with fresh histories
 * (docs/many.md, Limits). */
WETDEM_API int wetdem_sim_add_wall(struct wetdem_sim* sim, struct wetdem_vec3 point,
                                   struct wetdem_vec3 normal, int material);
/* Number of walls. */
WETDEM_API size_t wetdem_sim_n_walls(const struct wetdem_sim* sim);

/* Enables a built-in model by name for every pair (force models add up; one min-separation
 * model; one impulse model). Enabling a min-separation model replaces the previous one.
 * Returns WETDEM_OK, WETDEM_ERR_NOT_FOUND (message with a suggestion) or WETDEM_ERR_INVALID. */
WETDEM_API int wetdem_sim_enable_model(struct wetdem_sim* sim, const char* name);
/* Attaches a custom force model to this simulation only; params (model->params_size bytes;
 * NULL: the descriptors' defaults) are copied. Checked first: a name, a kind, the hooks the
 * kind needs (pair for force models, min_separation), a descriptor table (an empty {0} one
 * without parameters) and every value of params within its descriptor's range. Returns
 * WETDEM_OK, WETDEM_ERR_INVALID (with a message) or WETDEM_ERR_NOMEM. */
WETDEM_API int wetdem_sim_add_model(struct wetdem_sim* sim, const struct wetdem_model* model,
                                    const void* params);
/* Disables every force model and resets the min-separation model to "fixed". In the two-body
 * engine, after models are enabled or cleared between calls, the pair histories (tangential
 * springs, min-separation records) are kept only if the models that keep history are the same
 * ones in the same order, and otherwise start fresh (docs/engines.md, Pair list). */
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
/* Sets a parameter from text: an enumerated one by word, e.g. ("db.below_hmin", "nc"), any
 * other by a number as text ("1e-3", "0.5": a decimal point in any locale); checked as
 * wetdem_sim_set_param does. */
WETDEM_API int wetdem_sim_set_param_str(struct wetdem_sim* sim, const char* name,
                                        const char* value);
/* Reads a parameter by dotted name into *value. Returns WETDEM_OK, WETDEM_ERR_NOT_FOUND ("did
 * you mean ...") or WETDEM_ERR_INVALID (NULL name or value). */
WETDEM_API int wetdem_sim_param(const struct wetdem_sim* sim, const char* name, double* value);
/* Descriptor table ({0}-terminated, static) of the simulation settings, set as "sim.<name>"
 * (gravity, stop on separation, speed floor); the defaults are those of a new simulation. */
WETDEM_API const struct wetdem_param_desc* wetdem_sim_settings_params(void);

/* Evaluates the sum of the enabled force models for particles i and j (j may equal
 * (size_t)-1 - w to address wall w) with a fresh per-pair history (no tangential spring, no
 * min-separation record), at the current state; in the many-particle mode with j at its
 * periodic image nearest to i, as that engine pairs them. Writes the contact used into *c if
 * non-NULL.
 * Returns WETDEM_OK, WETDEM_ERR_INVALID (indices, an invalid particle, out NULL),
 * WETDEM_ERR_NUMERIC (a force that is not finite) or a model's negative status. */
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
/* Descriptor table ({0}-terminated, static) of integrator `name`'s parameters, set as
 * "<name>.<param>" (e.g. "cvode.rtol"); NULL for an unknown name. */
WETDEM_API const struct wetdem_param_desc* wetdem_integrator_params(const char* name);
/* One-line summary of integrator `name` (static text), or NULL for an unknown name. */
WETDEM_API const char* wetdem_integrator_summary(const char* name);

/* Shortest span t_end - t [s] that CVODE integrates (the cvode integrator and the pairwise
 * engine): below about 1e-160 s its step selection fails, so a shorter span is refused. The
 * cvode integrator also refuses (WETDEM_ERR_INVALID, state unchanged) a span below
 * 2 DBL_EPSILON |t_end|, which CVODE cannot tell from t (e.g. the next double after t). */
#define WETDEM_MIN_SPAN 1e-150

/* Advances the simulation to time t_end [s]. Returns WETDEM_OK at t_end, WETDEM_EVENT when a
 * stop condition fired (sim.stop_on_separation), or a negative status (message in errmsg).
 * A t_end equal to the current time does nothing; one before it, or one that is not finite,
 * is refused with WETDEM_ERR_INVALID and changes nothing. In the many-particle mode steps are
 * whole and time stays on the grid t0 + k dt: the run ends at its first point at or after
 * t_end - 1e-9 dt (wetdem_sim_time() tells which), so a t_end the run has already passed
 * within its latest step (t_end > t - dt (1 - 1e-9)) takes no step and returns WETDEM_OK; an
 * earlier one is refused. */
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
    /* Fixed-step integrators (verlet): the largest change of a pair's gap over one step that
     * crossed a branch gap h_k of its force laws inside their range (0 < h_k < range: h_min
     * and the like, docs/engines.md "Events"), as a multiple of h_k [-]. 0 when no step
     * crossed one, and always with cvode, which locates every crossing. Above
     * WETDEM_HMIN_STEP_RATIO_MAX the step does not resolve h_min: the result moves in steps,
     * not smoothly, with h_min (docs/engines.md, "Steps and h_min"). */
    double hmin_step_ratio;
};
/* Largest hmin_step_ratio (struct wetdem_stats) at which a fixed step counts as resolving
 * h_min: the gap moves at most a tenth of h_min in the step that crosses it [-]. */
#define WETDEM_HMIN_STEP_RATIO_MAX 0.1
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
    double time; /* [s] */
    enum wetdem_event_kind kind;
    size_t i, j; /* pair (j: wall index when is_wall) */
    bool is_wall;
    double gap; /* gap at the event [m] */
    double v_n; /* normal approach speed at the event [m/s] */
};
/* Name of an event kind, e.g. "contact_start". */
WETDEM_API const char* wetdem_event_kind_name(enum wetdem_event_kind kind);
/* Borrowed view of the event log, valid until the next integrate/reset. The log holds every
 * event since the simulation was created or reset (wetdem_collision_run starts it afresh):
 * each call of wetdem_sim_integrate appends its own, so a run in pieces logs each crossing
 * once, as one call does. */
WETDEM_API const struct wetdem_event_record* wetdem_sim_events(const struct wetdem_sim* sim,
                                                               size_t* n);

/* Called every `interval` seconds of simulated time (and at t = 0 and at the end; interval 0:
 * only there) with the current state; fn NULL removes the observer, and a run with one and an
 * interval that is not finite and >= 0 is refused (WETDEM_ERR_INVALID). A non-zero return
 * stops the integration with WETDEM_ERR_CALLBACK, the simulation left at the state and time
 * the observer saw (cvode: on its interpolant), from which a further wetdem_sim_integrate goes
 * on. */
typedef int (*wetdem_observer_fn)(const struct wetdem_sim* sim, void* ctx);
WETDEM_API void wetdem_sim_set_observer(struct wetdem_sim* sim, double interval,
                                        wetdem_observer_fn fn, void* ctx);
/* Read-only particle view for observers. */
WETDEM_API const struct wetdem_particle* wetdem_sim_particles_const(const struct wetdem_sim* sim,
                                                                    size_t* n);

/* Progress of a long run, for a caller that shows it (e.g. with the time left): called with
 * the simulated time t [s] the run has reached, the t_end [s] it runs to and the wall-clock
 * time [s] since the run began, after every WETDEM_PROGRESS_STEPS accepted steps of the
 * integrator and once more when the run ends without an error (at t_end, or where a stop
 * condition ended it). Successive calls of one run have non-decreasing t. It only observes:
 * it is given no state, it changes no step (not even CVODE's), and a run gives the same
 * results bit for bit with or without it. A non-zero return stops the run at that step with
 * WETDEM_ERR_CALLBACK (the state stays at the step; the return of the last call, when the run
 * has ended, is ignored). Used by wetdem_sim_set_progress and wetdem_pairwise_set_progress;
 * the many-particle mode has its own (wetdem_progress_fn). */
typedef int (*wetdem_time_progress_fn)(double t, double t_end, double elapsed, void* ctx);
#define WETDEM_PROGRESS_STEPS 64
/* Sets the progress callback of the two-body engine (verlet and cvode): each
 * wetdem_sim_integrate call, and so each wetdem_collision_run, is one run, from the call's
 * start to its t_end. fn NULL removes it. Kept by wetdem_sim_reset, not copied by
 * wetdem_sim_clone; not called in the many-particle mode (wetdem_many_settings.progress). */
WETDEM_API void wetdem_sim_set_progress(struct wetdem_sim* sim, wetdem_time_progress_fn fn,
                                        void* ctx);

/* ---- two-body collision analysis (SPEC §4) ---- */

enum wetdem_outcome {
    WETDEM_OUTCOME_NONE = -1,                 /* never interacted: a pairwise pair whose films
                                                 never met and that never touched, or a
                                                 collision whose striker had not reached the
                                                 interaction range by t_end */
    WETDEM_OUTCOME_STICK = 0,                 /* interacted, no separation by t_end */
    WETDEM_OUTCOME_STICK_ROTATE_SEPARATE = 1, /* separated after rotating as a doublet */
    WETDEM_OUTCOME_BOUNCE = 2,                /* separated promptly (contact-bounce) */
    WETDEM_OUTCOME_RECEDE = 3,                /* pairwise pair that separated without having
                                                 approached: it started inside (or at the edge
                                                 of) its films and only receded, untouched */
};
/* "none", "stick", "stick-rotate-separate", "bounce", "recede". */
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
    double angle;               /* impact angle [rad] in [0, pi/2): between the velocity of i
                                   and the line of centres at contact of the undisturbed
                                   straight-line approach, sin(angle) = b / (R_i + R_j) with
                                   the impact parameter b (wall: to its normal); 0 = head-on */
    struct wetdem_vec3 omega_i; /* initial spin of i [rad/s] */
    double initial_gap;         /* gap at t = 0 [m], finite and <= 1e150 (the geometry squares
                                   centre distances); <= 0: just outside the interaction range */
    double t_end;               /* longest simulated time [s], finite and > 0 (no automatic
                                   value here: the CLI derives one, docs/scenarios.md) */
    double observe_time;        /* > 0: also report e_n at this time (Punch Fig. 9 window) */
    double rebound_gap_factor;  /* separation is declared when the gap exceeds this multiple
                                   of the interaction range (>= 1; 0 means 1) */
    double close_gap;           /* [m] >= 0: gap below which the pair counts as a doublet for
                                   the stick-rotate-separate outcome; 0: the film thickness
                                   delta_ij when the pair has films, else 0.01 R* */
};

/* Result of a binary collision. e and e_n are 0 when the pair has not separated by t_end (no
 * rebound). */
struct wetdem_collision_result {
    double stokes_n;               /* normal Stokes number of the impact [-] */
    double speed_n0;               /* normal impact speed U cos(angle) [m/s] */
    double e;                      /* Nijssen: |dv_1|/|dv_0| of the relative velocity [-] */
    double e_n;                    /* normal restitution -v_f.n_f / v_0.n_0 (Punch Eq. 3) [-],
                                   n_f = normal_out */
    double e_t;                    /* tangential restitution of the contact-point velocity [-]
                                   (-1 smooth, +1 reversed; NAN without initial slip) */
    double e_n_observed;           /* e_n evaluated at observe_time (NAN if not requested) */
    double e_n_contact;            /* e_n referred to the line of centres at the last local
                                      minimum of the gap (the middle of the last contact) [-]:
                                      the contact's own restitution, free of the turn of the
                                      line while films part; NAN if the gap had no minimum, 0
                                      when not separated */
    double angle_in, angle_out;    /* impact angle of the straight-line approach (= spec angle)
                                   and rebound angle of the relative velocity, to the normal
                                   [rad] */
    struct wetdem_vec3 normal_out; /* n_f: the unit line of centres (from j to i) that the
                                      rebound is referred to: where the films last parted
                                      (film-coated pairs); without films, at the last local
                                      minimum of the gap, or where a stick-rotate-separate
                                      doublet left close_gap; at the end if none of these */
    struct wetdem_vec3 omega_i, omega_j; /* final spins [rad/s] */
    double contact_duration;             /* total time with gap < 0 [s] */
    double interaction_duration;         /* time from first interaction to separation [s] */
    double min_gap;                      /* smallest gap reached [m] */
    bool solid_contact;                  /* gap reached 0 */
    bool hmin_reached;                   /* gap reached h_min */
    bool separated;                      /* left the interaction range by t_end */
    double energy_ratio;        /* energy of the relative motion and spins, plus that stored
                                   by the conservative forces at the gap (elastic overlap,
                                   capillary well: docs/engines.md), at the end over that at
                                   the start [-]: at most 1 in the passive models (up to the
                                   integration error), < 0 when bound in a capillary well;
                                   NAN with gravity */
    double rotation_angle;      /* angle the line of centres turned during interaction [rad] */
    double rotation_close;      /* the part of rotation_angle turned after the approach was
                                   first arrested (first minimum of the gap) while the gap was
                                   below close_gap [rad] */
    double rotation_doublet;    /* the part of rotation_close that the relative velocity turned
                                   with, the same way (the doublet's orbit; free flight past the
                                   target and the impact turn only one of the two) [rad]: above
                                   5 deg a separated pair is stick-rotate-separate */
    double close_gap;           /* the doublet gap used (spec close_gap or automatic) [m] */
    double t_first_interaction; /* time the gap first reached the interaction range [s]
                                   (0 when starting inside it) */
    double t_final;             /* time of the final state: separation or t_end [s] */
    enum wetdem_outcome outcome;
    struct wetdem_stats stats; /* the integrator's counts; also when the run failed (those up
                                  to the failure; every other field is then 0) */
};

/* Sets up and runs one binary collision on `sim` (its particles are replaced; its materials,
 * fluid, models, integrator and parameters are used) with the two-body engine: refused
 * (WETDEM_ERR_INVALID) in the many-particle mode. Returns WETDEM_OK or a negative status.
 * The event log of the run stays available through wetdem_sim_events(). */
WETDEM_API int wetdem_collision_run(struct wetdem_sim* sim,
                                    const struct wetdem_collision_spec* spec,
                                    struct wetdem_collision_result* result);
/* Removes all particles and walls, the event log, pair histories and statistics, and sets
 * the time to 0; materials, fluid, models and parameters are kept. In the many-particle mode
 * the mode and its settings stay, and its state starts afresh (step 0, a new energy budget). */
WETDEM_API void wetdem_sim_reset(struct wetdem_sim* sim);
/* Deep copy (materials, fluid, models, parameters, integrator, particles, walls, time, pair
 * histories, event log; not the observer, and not the many-particle mode: the copy is in the
 * two-body mode). NULL if out of memory. For running independent collisions in parallel. */
WETDEM_API struct wetdem_sim* wetdem_sim_clone(const struct wetdem_sim* sim);

/* ======================================================================================== */
/* Many particles: cell lists, boxes, insertion, outputs, energy budget, checkpoints         */
/* (docs/many.md)                                                                           */
/* ======================================================================================== */

/* Called every progress_every steps of a many-particle run with the steps done and the total
 * of this integrate call and the wall-clock time since its start [s]. A non-zero return stops
 * the run like the stop flag. */
typedef int (*wetdem_progress_fn)(unsigned long long done, unsigned long long total, double elapsed,
                                  void* ctx);

/* Settings of the many-particle mode. Zero-initialise, then set what you need. */
struct wetdem_many_settings {
    double skin;                         /* Verlet skin of the cell lists [m] >= 0; 0: 0.1 x
                                            the smallest radius */
    bool periodic[3];                    /* periodic axes x, y, z */
    struct wetdem_vec3 box_lo, box_hi;   /* periodic box [m] (read on periodic axes only) */
    double dt;                           /* step [s] >= 0; 0: verlet.dt, or derived from the
                                            contact times of the pairs that can occur, the
                                            viscous relaxation and h_min (docs/many.md, Time
                                            step) */
    bool energy_budget;                  /* accumulate the work of every model (costs about
                                            25-50 %: docs/many.md, "Energy budget") */
    const char* output_prefix;           /* <prefix>_NNNNNN.vtk, <prefix>.vtk.series and
                                            <prefix>.csv; NULL: no files (copied) */
    unsigned long long vtk_every;        /* steps between VTK files; 0: none */
    bool vtk_binary;                     /* binary instead of ASCII VTK */
    bool vtk_links;                      /* with each VTK file, <prefix>_links_NNNNNN.vtk
                                            (wetdem_sim_write_vtk_links) and the index
                                            <prefix>_links.vtk.series
                                            (WETDEM_LINKS_SUFFIX) */
    unsigned long long csv_every;        /* steps between rows of global quantities; 0: none */
    const char* checkpoint_path;         /* NULL: no checkpoints (copied) */
    unsigned long long checkpoint_every; /* steps between checkpoints; 0: only when stopped */
    volatile int* stop_flag;             /* read every step; non-zero: write the checkpoint and
                                            return WETDEM_EVENT (e.g. set by a SIGINT handler) */
    wetdem_progress_fn progress;         /* optional progress callback */
    void* progress_ctx;
    unsigned long long progress_every; /* steps between progress calls; 0: 1000 */
    const char* csv_comment;           /* the first lines of <prefix>.csv, each written as a
                                          "# " comment: its provenance (the CLI's "wetdem
                                          VERSION (git HASH)" and "command: ..."); NULL or
                                          "": "wetdem VERSION" (copied) */
    const char* checkpoint_note;       /* text every checkpoint records, which
                                          wetdem_sim_checkpoint_note gives back after a restore
                                          (the CLI's: the names of its VTK frames and CSV, that
                                          a restart must continue); NULL or "": none (copied) */
};

/* Most steps one wetdem_sim_integrate() call of a many-particle run takes: a longer call is
 * refused (a 2-core machine does some 1e7 particle-steps a second). */
#define WETDEM_MANY_MAX_STEPS 1e15
/* What links files add to the name of their frames and index: <prefix>_links_NNNNNN.vtk beside
 * <prefix>_NNNNNN.vtk, <prefix>_links.vtk.series (the library's frames and the CLI's alike). */
#define WETDEM_LINKS_SUFFIX "_links"

/* Switches sim to the many-particle mode: wetdem_sim_integrate() then runs velocity Verlet
 * over cell lists (no event location), with walls, gravity, periodic axes, OpenMP, outputs and
 * checkpoints as set. NULL switches back. Returns WETDEM_OK or WETDEM_ERR_INVALID. On a started
 * run it starts the mode afresh from the current particles and time: step 0, a new step, fresh
 * pair histories and energy budget, outputs numbered from 0. The models of a started run stay
 * those it started with: after models are enabled or cleared, wetdem_sim_integrate and the
 * reports of the run refuse (WETDEM_ERR_INVALID) until they are enabled again as they were or
 * the mode is started afresh; parameters, fluid and gravity may change between calls
 * (docs/many.md, Limits). */
WETDEM_API int wetdem_sim_set_many(struct wetdem_sim* sim, const struct wetdem_many_settings* s);

#define WETDEM_ENERGY_MAX_MODELS 16

/* Energy budget of a many-particle run since its start [J]. work_* > 0 means energy given to
 * the particles, < 0 taken from them (dissipated, or stored as by a contact spring). */
struct wetdem_energy_budget {
    double kinetic;    /* translational + rotational kinetic energy now */
    double potential;  /* gravitational potential energy now, -sum m g.x */
    double elastic;    /* energy stored now in the solid contacts of the enabled models (their
                          elastic_energy: Hertz (8/15) E* sqrt(R*) delta^(5/2), hooke
                          k delta^2 / 2, nijssen's blended contact; 0 for fluid forces) */
    double input;      /* kinetic + potential + elastic at the start */
    double dissipated; /* input - (kinetic + potential + elastic): lost to damping, friction,
                          viscous forces, plus what capillary bridges and tangential springs
                          hold */
    size_t n_models;   /* enabled force models (wetdem_sim_model(sim, k) names them) */
    double work_pair[WETDEM_ENERGY_MAX_MODELS]; /* work of model k in particle pairs */
    double work_wall[WETDEM_ENERGY_MAX_MODELS]; /* work of model k in particle-wall pairs */
    double work_total;                          /* sum of all work */
    double balance_error; /* (kinetic + potential) - (their start values) - work_total: zero
                             up to the O(dt^2) integration error */
};
/* Fills *b. WETDEM_OK, or WETDEM_ERR_INVALID before a run or when many.energy_budget is off
 * (no work is summed then, so no budget can close). */
WETDEM_API int wetdem_sim_energy_budget(const struct wetdem_sim* sim,
                                        struct wetdem_energy_budget* b);

/* Global quantities at the latest force evaluation of a many-particle run. */
struct wetdem_many_stats {
    size_t contacts;                /* particle pairs and particle-wall pairs where an enabled
                                       model exerts a solid-contact force (is_in_contact) */
    size_t bridges;                 /* particle pairs joined by the liquid bridge of an
                                       enabled film model (is_bridged: h <= film) */
    size_t agglomerates;            /* clusters of >= 2 particles joined by bridges */
    double mean_agglomerate;        /* their mean number of particles (0 if none) */
    size_t candidate_pairs;         /* pairs in the neighbour list */
    unsigned long long list_builds; /* neighbour-list builds so far */
    double dt;                      /* step [s] */
    unsigned long long step;        /* steps since the start of the many run */
    /* wall-clock time by phase of the many run in this process [s] (a restart starts them at
       zero): kicks and drifts, force passes (less their neighbour-list builds), the builds
       (with the history carried over), and each step's outputs and observer calls */
    double seconds_kick, seconds_forces, seconds_lists, seconds_output;
    int threads; /* OpenMP threads the run's loops use: OMP_NUM_THREADS, or 1 for fewer than 512
                    particles (waking the threads would cost more than the work) */
    double relaxation_time; /* shortest viscous relaxation time of the enabled models at the
                               start, or at the restored state after a checkpoint [s], which
                               dt stays below (INFINITY: nothing damps) */
    /* shortest contact time, normal or tangential, of the pairs that can occur, at the speed
       scale, then [s]: verlet.dt_fraction multiplies it; a dt above
       WETDEM_MANY_CONTACT_FRACTION_MAX of it does not resolve the contacts (INFINITY: no pair
       can touch) */
    double contact_time;
    /* time in which a pair closing at the speed scale crosses the smallest gap where the
       enabled force laws jump (h_min, below_hmin = c), then [s]: verlet.many_hmin_fraction
       multiplies it; a longer dt crosses the jump within one step (INFINITY: none jumps) */
    double hmin_crossing_time;
    /* The speeds behind those time scales (docs/many.md, "Speeds beyond the step's"): the speed
       scale V they were evaluated at when the run started, 2 v0 + sqrt(2 |g| H) floored at
       sim.speed_floor, v0 the largest particle speed then and H the fall of "What a fall
       adds" [m/s]; the speed B = V - v0 no particle exceeds where H bounds the fall and the
       contacts and films take energy rather than give it (INFINITY with gravity but no walls
       or fixed spheres: all falls together) [m/s]; and the largest speed u a free particle has
       had since the start, over the half-step velocities of every step [m/s]. Where u > B the
       time scales above do not hold: wetdem_sim_many_time_scales_at gives them at V + u - B,
       the speed scale with u in place of B. A checkpoint keeps all three, so a resumed run
       reports those of the whole run. */
    double speed_scale, speed_bound, largest_speed;
};
/* The largest step, as a fraction of wetdem_many_stats.contact_time, that resolves the
 * contacts: velocity Verlet is unstable for a Hertz contact from about 0.5 of it, and a dry
 * Hertz impact's restitution is off by 0.1 % at 0.1 and 0.9 % at 0.2 (docs/many.md, Time
 * step). `wetdem run` warns above it, and above hmin_crossing_time. */
#define WETDEM_MANY_CONTACT_FRACTION_MAX 0.1
WETDEM_API int wetdem_sim_many_stats(const struct wetdem_sim* sim, struct wetdem_many_stats* s);
/* The speeds of wetdem_many_stats alone (speed_scale, speed_bound, largest_speed [m/s]), bit
 * for bit those it reports, without its pass over the pairs for the contacts, bridges and
 * agglomerates (which allocates): cheap enough to check the speeds between any two integrate
 * calls. Returns WETDEM_OK, or WETDEM_ERR_INVALID (not a started many run, a NULL output, or
 * models enabled or cleared since the run started, as wetdem_sim_many_stats refuses), the
 * outputs then unchanged. */
WETDEM_API int wetdem_sim_many_speeds(const struct wetdem_sim* sim, double* speed_scale,
                                      double* speed_bound, double* largest_speed);
/* The time scales of a started many-particle run that wetdem_many_stats reports
 * (contact_time, relaxation_time, hmin_crossing_time), evaluated as when the run started but
 * with the pairs closing and sliding at `speed` [m/s] instead of the speed scale, for the
 * particles and walls as they are now: e.g. at speed_scale + largest_speed - speed_bound, to
 * see whether the step resolves what the run has met; and the step a run starting at that
 * speed would derive (*step: verlet.dt_fraction x contact_time, relaxation_time / 4 and
 * verlet.many_hmin_fraction x hmin_crossing_time, the shortest). The run is not changed.
 * Returns WETDEM_OK,
 * WETDEM_ERR_INVALID (not a started many run, a NULL output, a speed not finite and > 0, or
 * a model that meets the edge of its range at that speed: nijssen, whose h_min grows with the
 * approach speed; message names it), WETDEM_ERR_NOMEM. */
WETDEM_API int wetdem_sim_many_time_scales_at(struct wetdem_sim* sim, double speed,
                                              double* contact_time, double* relaxation_time,
                                              double* hmin_crossing_time, double* step);

/* How the header line of a many-particle run's CSV (output_prefix.csv) begins, after its '#'
 * lines: the time and step columns; the columns after them depend on the models and the energy
 * budget (docs/many.md, Outputs). A reader of the file finds its header by it. */
#define WETDEM_MANY_CSV_HEAD "time [s],step [count],"
/* Appends a row of the global quantities at the current state to the run's CSV
 * (output_prefix.csv), with the columns and format of the rows written every csv_every steps:
 * e.g. the state a run ends or is interrupted at, off that grid. WETDEM_ERR_INVALID before a
 * run or without outputs, WETDEM_ERR_IO. */
WETDEM_API int wetdem_sim_many_write_csv_row(struct wetdem_sim* sim);

/* Writes the particles as a legacy VTK file (radius, velocity, spin, contacts as in
 * wetdem_many_stats, material, id). */
WETDEM_API int wetdem_sim_write_vtk(struct wetdem_sim* sim, const char* path, bool binary);

/* Writes the links of a started many-particle run as a legacy VTK file of lines: each
 * particle pair in contact or joined by a liquid bridge, and each particle-wall contact (as
 * wetdem_many_stats counts them), each liquid bridge to a wall (bridge 1; the counts leave
 * them out), and each other particle or particle-wall pair on which a
 * model exerts a force (lubrication between surfaces apart: nijssen, reynolds; contact and
 * bridge 0), from centre to centre (across periodic boundaries, to the
 * nearest image) or from the centre to the wall, with the cell data i, j (-1 - w for wall w),
 * contact, bridge, gap [m], force_normal [N] (> 0 repulsive), force_tangential [N] and force
 * (the vector on i, on j its opposite) [N]: the
 * force of the enabled models at this state, with the pairs' histories as the latest step
 * left them (docs/many.md, Outputs). WETDEM_ERR_INVALID before a run, WETDEM_ERR_IO. */
WETDEM_API int wetdem_sim_write_vtk_links(struct wetdem_sim* sim, const char* path, bool binary);
/* The simulated time [s] of a particle file that wetdem_sim_write_vtk or a many-particle run
 * wrote (ASCII or binary), into *t, read from its title line "wetdem particles t = T s": the
 * time written, bit for bit. *t is set only on success. Returns WETDEM_OK, WETDEM_ERR_INVALID
 * (path or t NULL), WETDEM_ERR_IO (the file cannot be opened or read), WETDEM_ERR_PARSE (no
 * such title: another file, a links file, a title cut short, altered or with anything after
 * " s", a time that is not finite) or WETDEM_ERR_NOMEM (no C locale could be made). */
WETDEM_API int wetdem_output_vtk_frame_time(const char* path, double* t);
/* One entry of a ".vtk.series" index as wetdem writes them, the line
 * { "name" : "NAME", "time" : T } (comma after it or not): NAME, its JSON escapes \" and \\
 * undone, into name (n bytes) and T [s] into *time, both set only on success. Returns
 * WETDEM_OK, WETDEM_ERR_PARSE (no such entry: the index's other lines, an empty or
 * unterminated name, one of n bytes or more, a time missing or not finite), WETDEM_ERR_INVALID
 * (a NULL argument or n = 0) or WETDEM_ERR_NOMEM. */
WETDEM_API int wetdem_output_vtk_series_entry(const char* line, char* name, size_t n, double* time);
/* Writes a checkpoint of a many-particle run (atomic: temporary file, then rename).
 * Returns WETDEM_OK, WETDEM_ERR_INVALID (not in many mode) or WETDEM_ERR_IO. */
WETDEM_API int wetdem_sim_write_checkpoint(struct wetdem_sim* sim, const char* path);
/* Restores a checkpoint into a sim set up exactly as the one that wrote it (materials, fluid,
 * models, parameters, walls, many settings): particles, time, step, pair histories, energy
 * budget and output counters are replaced; continuing gives bit-identical results to the
 * uninterrupted run. The outputs go on at the multiples of the vtk_every, csv_every and
 * checkpoint_every of the settings set now, which may differ from those of the run that
 * wrote the checkpoint. WETDEM_ERR_INVALID if the set-up differs, WETDEM_ERR_PARSE/IO if the
 * file is bad. */
WETDEM_API int wetdem_sim_read_checkpoint(struct wetdem_sim* sim, const char* path);
/* The checkpoint_note of the checkpoint that wetdem_sim_read_checkpoint last restored into
 * sim: "" when it holds none (its run set none, or an earlier version wrote it); NULL when no
 * checkpoint was restored since the many-particle mode was set (or sim is NULL). Valid until
 * the next restore or wetdem_sim_set_many. */
WETDEM_API const char* wetdem_sim_checkpoint_note(const struct wetdem_sim* sim);

enum wetdem_insert_layout {
    WETDEM_INSERT_LATTICE = 0, /* simple cubic lattice of spacing 2 R_max + gap, x fastest */
    WETDEM_INSERT_RANDOM = 1,  /* random sequential addition, largest spheres first */
};

/* What to insert and where. Seeded: the same spec gives bit-identical particles. */
struct wetdem_insert_spec {
    enum wetdem_insert_layout layout;
    size_t n;                    /* number of spheres, >= 1 (at most SIZE_MAX / (2 x
                                    sizeof(struct wetdem_particle))) */
    struct wetdem_vec3 lo, hi;   /* region [m]; spheres lie inside it on non-periodic axes */
    bool periodic[3];            /* axes on which the region wraps (overlaps through images) */
    double radius_min;           /* radii uniform in [radius_min, radius_max] [m], > 0 */
    double radius_max;           /* [m], >= radius_min */
    const double* radii;         /* optional: n radii [m] used instead of the uniform draw */
    double gap;                  /* least surface gap between spheres and to the region's
                                    faces on non-periodic axes [m], >= 0 */
    struct wetdem_vec3 velocity; /* mean velocity [m/s] */
    double velocity_sigma;       /* standard deviation of each velocity component [m/s] >= 0 */
    int material;                /* material index given to every sphere */
    unsigned long seed;          /* seed of the gsl_rng mt19937 generator */
    size_t max_attempts;         /* random layout: trials per sphere; 0 means 10000 */
    wetdem_progress_fn progress; /* optional, random layout: called with the spheres placed,
                                    n and the wall time since the start [s] after every
                                    WETDEM_INSERT_PROGRESS_EVERY spheres and the last; a
                                    non-zero return stops the insertion (WETDEM_EVENT, no
                                    sphere inserted) */
    void* progress_ctx;
};
#define WETDEM_INSERT_PROGRESS_EVERY 1000
/* Inserts spec->n spheres into sim (mass from the material density). The random layout keeps
 * spec->gap clear of the spheres already in sim too (minimum image on the region's periodic
 * axes), so groups can share a region; the lattice does not look at them. Returns WETDEM_OK,
 * WETDEM_ERR_INVALID (bad spec, or the region cannot hold them: the message says how many
 * fit and what to change), WETDEM_ERR_NOMEM, or WETDEM_EVENT when the progress callback
 * stopped it (nothing is inserted unless WETDEM_OK). */
WETDEM_API int wetdem_sim_insert(struct wetdem_sim* sim, const struct wetdem_insert_spec* spec);

/* ======================================================================================== */
/* Pairwise engine (Davis 2023)                                                             */
/* ======================================================================================== */

/* ---- pairwise engine section ---- */

/* Davis's relative-motion formulation (Sec. II) for a few film-coated spheres moving in the
 * x-y plane: per tracked pair the gap h, line-of-centres angle theta, normal approach speed
 * v_n, rotation rate Omega of the line of centres and spin sum v_omega = a_i w_i + a_j w_j
 * (Eqs. 9, 14, 17, 18); sphere 0 in fixed coordinates (Eqs. 34-36, 39); the other pairs from
 * geometry (Appendix B). Film forces (Eqs. 3-4) act while a pair's films overlap
 * (h <= delta_i + delta_j); at h = h_min a hard-sphere impulse (Appendix A) reverses the
 * approach. Adaptive integration (CVODE BDF) with located events. docs/derivations/pairwise.md.
 * Sign conventions follow Davis: theta_ij is the angle of x_j - x_i from the x axis, v_n > 0
 * approaching, spins counter-clockwise positive. */

#define WETDEM_PAIRWISE_MAX_SPHERES 8
#define WETDEM_PAIRWISE_MAX_PAIRS 28 /* MAX_SPHERES (MAX_SPHERES - 1) / 2 */
/* Smallest h_min / (a_i + a_j) of a pairwise run: the gap of a pair outside the tracked tree
 * (three spheres touching in a loop) is a difference of lengths of the spheres' size and is
 * resolved to about this (docs/derivations/pairwise.md Sec. 8). For Davis's groups:
 * film_ratio x hmin_ratio >= this. */
#define WETDEM_PAIRWISE_MIN_HMIN_RATIO 5e-11

/* One sphere of a pairwise run, in the x-y plane. */
struct wetdem_pairwise_sphere {
    double radius; /* a_i [m] > 0 */
    double mass;   /* m_i [kg] > 0 */
    double film;   /* liquid film thickness delta_i [m] >= 0 */
    double x, y;   /* centre [m] */
    double vx, vy; /* velocity [m/s] */
    double omega;  /* spin about +z, counter-clockwise positive [rad/s] */
};

/* Input of a pairwise run (plain data; fill with wetdem_pairwise_config_init first). */
struct wetdem_pairwise_config {
    size_t n_spheres; /* 2..WETDEM_PAIRWISE_MAX_SPHERES */
    struct wetdem_pairwise_sphere spheres[WETDEM_PAIRWISE_MAX_SPHERES];
    double viscosity;            /* mu [Pa s] >= 0 */
    double surface_tension;      /* sigma [N/m] >= 0 (capillary suction 8 pi a_ij sigma) */
    double h_min;                /* minimum separation where solid-like contact occurs [m] > 0 */
    double restitution;          /* e_dry (0, 1] */
    double friction;             /* mu_f of the contact impulse [-] >= 0 */
    double gravity_x, gravity_y; /* [m/s^2] */
    double t_end;                /* longest simulated time [s], in [WETDEM_MIN_SPAN, 1e9] */
    double rtol;                 /* relative tolerance of the integrator, [1e-14, 1e-5]; 1e-9 */
    double rest_speed_ratio;     /* contacts slower than this x v_n0 (without v_n0 > 0: x the
                                    largest initial sphere speed), and when > 0 at least those
                                    whose kinetic energy is within 1e4 x the energy the reset
                                    of the gap to h_min adds (docs/derivations/pairwise.md),
                                    become resting [-]; 1e-3 */
    bool stop_when_separated;    /* stop once every pair is apart and receding (default true) */
    size_t ref_i, ref_j;         /* reference pair for v_n0, delta_12, t-hat, t* (default 0, 1) */
    size_t max_events;           /* event budget (default 100000) */
    bool energy_budget;          /* integrate the viscous work for result.energy (default
                                    true; about a third more time); false: energy is NAN */
};

/* What happened, in the event log of a pairwise run. */
enum wetdem_pairwise_event_kind {
    WETDEM_PAIRWISE_FILM_START = 1,     /* films of pair (i, j) begin to overlap: h = delta_ij */
    WETDEM_PAIRWISE_CONTACT = 2,        /* h = h_min approaching: hard-sphere impulse */
    WETDEM_PAIRWISE_REST_START = 3,     /* contact slower than the rest speed: pair held at h_min */
    WETDEM_PAIRWISE_REST_END = 4,       /* the held pair's contact force fell to zero */
    WETDEM_PAIRWISE_FILM_END = 5,       /* films separate: h = delta_ij receding */
    WETDEM_PAIRWISE_PARTNER_CHANGE = 6, /* tracked pair (i, j) replaced tracked pair (k, l) */
};

/* One entry of the event log. */
struct wetdem_pairwise_event {
    enum wetdem_pairwise_event_kind kind;
    double time;   /* [s] */
    double t_hat;  /* v_n0 t / delta_12 [-] (Davis Eq. 19); NAN without v_n0 > 0 */
    double t_star; /* v_10 t / 4a [-]; NAN without v_10 > 0 */
    size_t i, j;   /* pair */
    size_t k, l;   /* partner change: the pair that left the tracked set; else = i, j */
    double gap;    /* h at the event [m] */
    double v_n;    /* normal approach speed just before the event [m/s] */
};

/* Outcome of a run of three or more spheres (two: FA = stick, FS = separated). */
enum wetdem_pairwise_outcome {
    WETDEM_PAIRWISE_FA = 0, /* full agglomeration: one cluster of overlapping films */
    WETDEM_PAIRWISE_PA = 1, /* partial agglomeration: some spheres left, some stay together */
    WETDEM_PAIRWISE_FS = 2, /* full separation: every pair apart */
};

/* Per-pair summary of a run. */
struct wetdem_pairwise_pair_result {
    size_t i, j;
    bool films_met;      /* the films overlapped at some time */
    bool bound;          /* films still overlapping (or held at h_min) at the end */
    unsigned n_contacts; /* hard-sphere impulses */
    double v_n_in;       /* normal approach speed when the films first overlapped [m/s] */
    double v_n_out;      /* normal separation speed at the last film separation [m/s] */
    double e_wet;        /* Eq. 40: v_n_out / v_n0 (0 if bound, NAN if films never met or
                            v_n0 <= 0) [-] */
    double e_wet_own;    /* v_n_out / v_n_in (NAN if v_n_in <= 0 or films never met) [-] */
    double t_start;      /* first film overlap [s] (NAN if none) */
    double t_end;        /* last film separation [s] (NAN if none) */
    double min_gap;      /* smallest gap seen at step ends and events [m] */
    int mechanism;       /* enum wetdem_outcome: stick (bound at the end),
                           stick-rotate-separate (its approach reversed by the film and
                           centrifugal forces), bounce (reversed by an impulse, its own or a neighbour's that
                           knocked it apart; a pair without films: touched), recede (films
                           overlapping from the start, never approached, never touched) or
                           none (WETDEM_OUTCOME_NONE = -1: films never met, never touched) */
};

/* Energy budget of a pairwise run [J]. The mechanical energy is the kinetic energy
 * (translation and spin) plus two potentials: the capillary suction's, sum over the pairs
 * whose films overlap of 8 pi a sigma (h - delta) <= 0 (zero where the films meet, so it is
 * continuous), and gravity's, -sum m g . (x - x_0) from the start. Its loss is the work of the viscous film forces
 * (integrated along the run) and of the impulses:
 *     initial = kinetic + capillary + gravity + viscous_normal + viscous_tangential
 *               + contact + residual,
 * where the residual is the integration error (docs/derivations/pairwise.md, Sec. 11). */
struct wetdem_pairwise_energy {
    double initial;            /* mechanical energy at t = 0, before any impulse [J] */
    double kinetic;            /* kinetic energy at the end [J] */
    double capillary;          /* capillary potential at the end, <= 0 [J] */
    double gravity;            /* gravity's potential -sum m g . (x - x_0) at the end [J] */
    double viscous_normal;     /* dissipated by the viscous part of Eq. 3, >= 0 [J] */
    double viscous_tangential; /* dissipated by Eq. 4, >= 0 [J] */
    double contact;            /* lost in impulses: e_dry < 1, friction, rest contacts [J] */
    double residual;           /* initial less all the others [J] */
};

/* Summary of a pairwise run. */
struct wetdem_pairwise_result {
    size_t n_spheres, n_pairs;
    struct wetdem_pairwise_pair_result pairs[WETDEM_PAIRWISE_MAX_PAIRS]; /* order of
                                          wetdem_pairwise_pair_index() */
    enum wetdem_pairwise_outcome outcome;
    int separated_sphere; /* PA with one sphere alone: its index; else -1 */
    struct wetdem_pairwise_sphere final[WETDEM_PAIRWISE_MAX_SPHERES]; /* state at the end */
    double time;                                                      /* time reached [s] */
    double v_n0;      /* normal approach speed of the reference pair at t = 0 [m/s]: the
                         scale of t-hat and e_wet, which are NAN when it is <= 0 (a pair at
                         rest or receding, as in a cluster relaxing from rest) */
    double delta_ref; /* delta_12 of the reference pair [m] */
    double v_10;      /* speed of sphere ref_i at t = 0 [m/s] */
    double a_ref;     /* reduced radius a of the reference pair [m] */
    size_t n_events;
    unsigned long long steps, rhs_evals, guard_evals;
    struct wetdem_pairwise_energy energy;
};

/* State of every sphere at one output time, handed to the observer. */
struct wetdem_pairwise_frame {
    double time, t_hat, t_star; /* [s], [-], [-] */
    size_t n_spheres, n_pairs;
    struct wetdem_pairwise_sphere spheres[WETDEM_PAIRWISE_MAX_SPHERES];
    double gap[WETDEM_PAIRWISE_MAX_PAIRS]; /* h of every pair [m] */
    double v_n[WETDEM_PAIRWISE_MAX_PAIRS]; /* normal approach speed of every pair [m/s] */
    struct wetdem_pairwise_energy energy;  /* the budget from t = 0 to this time (NAN without
                                              config.energy_budget) */
};
/* Observer: called at t = 0, every `interval` seconds and at the end; non-zero stops the run
 * with WETDEM_ERR_CALLBACK. */
typedef int (*wetdem_pairwise_observer_fn)(const struct wetdem_pairwise_frame* frame, void* ctx);

/* Dimensionless inputs of Davis Table I for equal spheres (radius 2a, reduced radius a). */
struct wetdem_pairwise_davis {
    double n_spheres;   /* 2 (striker and target only) or 3 [-] */
    double stokes;      /* St_n = m v_n0 / (6 pi mu a^2) > 0 */
    double capillary;   /* Ca = 3 mu a v_n0 / (sigma delta_12) > 0; 0 or INFINITY: none */
    double film_ratio;  /* h_a = delta_12 / 4a, (0, 0.5) */
    double hmin_ratio;  /* h_m = h_min / delta_12, (0, 1) */
    double angle_deg;   /* impact angle beta = alpha - theta_12,0 [deg], [0, 90) */
    double d23, d13;    /* delta_23 / delta_12 and delta_13 / delta_12 (> 0, triangle rule) */
    double h23;         /* h_23,0 / delta_12 >= hmin_ratio */
    double theta23_deg; /* theta_23,0, angle of x_3 - x_2 from the x axis [deg], [-180, 180] */
    double restitution; /* e_dry (0, 1] */
    double friction;    /* mu_f >= 0 */
    double t_star_end;  /* run length in t* = v_10 t / 4a, > 0 */
    double a;           /* reduced radius [m] (scale only; results depend on the groups) */
    double viscosity;   /* mu [Pa s] (scale only) */
    double speed_n0;    /* v_n0 [m/s] (scale only) */
};

/* A pairwise run object (opaque): integrator workspace, event log, last error message. */
struct wetdem_pairwise;

/* Allocates a run object (holds the integrator, event log and messages). NULL if out of
 * memory. */
WETDEM_API struct wetdem_pairwise* wetdem_pairwise_create(void);
/* Frees a run object; NULL does nothing. */
WETDEM_API void wetdem_pairwise_free(struct wetdem_pairwise* pw);
/* Last error message of the run object, "" if none. */
WETDEM_API const char* wetdem_pairwise_errmsg(const struct wetdem_pairwise* pw);
/* Fills *cfg with defaults (no spheres, e_dry 1, mu_f 0, rtol 1e-9, ...). */
WETDEM_API void wetdem_pairwise_config_init(struct wetdem_pairwise_config* cfg);
/* Checks a configuration; a message naming the parameter, value and valid range goes to
 * msg (spheres counted from 1 as in the CLI and output columns, with the array index:
 * "spheres 1 and 2 (spheres[0], spheres[1])"). Returns WETDEM_OK or WETDEM_ERR_INVALID. */
WETDEM_API int wetdem_pairwise_config_validate(const struct wetdem_pairwise_config* cfg, char* msg,
                                               size_t msg_size);
/* Sets the observer called every `interval` seconds [s] of a run; fn NULL removes it. A run
 * with an observer and an interval that is not finite and > 0 is refused (WETDEM_ERR_INVALID). */
WETDEM_API void wetdem_pairwise_set_observer(struct wetdem_pairwise* pw, double interval,
                                             wetdem_pairwise_observer_fn fn, void* ctx);
/* Sets the progress callback (wetdem_time_progress_fn) of the runs of pw: t from 0 to
 * cfg.t_end, elapsed from the start of wetdem_pairwise_run; a non-zero return stops the run
 * with WETDEM_ERR_CALLBACK, as a failed run (*res holds no result). fn NULL removes it. */
WETDEM_API void wetdem_pairwise_set_progress(struct wetdem_pairwise* pw, wetdem_time_progress_fn fn,
                                             void* ctx);
/* Runs one collision from cfg (copied) and fills *res. Returns WETDEM_OK, or a negative
 * status with the message in wetdem_pairwise_errmsg(); *res then holds no result (zeroed, with
 * some fields filled up to the failure: time, final and n_events stay 0), and the event log
 * the events up to it. The event log stays readable until the next run. One run object may
 * run any number of configurations one after the other: each run is bit-identical to the
 * same run on a new object. */
WETDEM_API int wetdem_pairwise_run(struct wetdem_pairwise* pw,
                                   const struct wetdem_pairwise_config* cfg,
                                   struct wetdem_pairwise_result* res);
/* Borrowed view of the last run's event log; *n receives the count. */
WETDEM_API const struct wetdem_pairwise_event*
wetdem_pairwise_events(const struct wetdem_pairwise* pw, size_t* n);
/* The scaled times of a run's time t [s]: t-hat = v_n0 t / delta_12 (Davis Eq. 19) and
 * t* = v_10 t / 4a, NAN when their speed (res->v_n0, res->v_10) is not positive. */
WETDEM_API double wetdem_pairwise_t_hat(const struct wetdem_pairwise_result* res, double t);
WETDEM_API double wetdem_pairwise_t_star(const struct wetdem_pairwise_result* res, double t);
/* Index of pair (i, j), i != j < n, in the per-pair arrays: (0,1), (0,2), ..., (1,2), ...;
 * (i, j) and (j, i) are the same pair. SIZE_MAX when i == j, i >= n or j >= n (no pair). */
WETDEM_API size_t wetdem_pairwise_pair_index(size_t n, size_t i, size_t j);
/* "film_start", "contact", "rest_start", "rest_end", "film_end", "partner_change". */
WETDEM_API const char* wetdem_pairwise_event_name(enum wetdem_pairwise_event_kind kind);
/* "FA", "PA", "FS". */
WETDEM_API const char* wetdem_pairwise_outcome_name(enum wetdem_pairwise_outcome outcome);
/* Largest magnitude among the terms of an energy budget [J] (DBL_MIN if all are zero): the
 * scale its residual is judged against. NAN when a term (the residual aside) is NaN, as in a
 * budget not computed (config.energy_budget false). */
WETDEM_API double wetdem_pairwise_energy_scale(const struct wetdem_pairwise_energy* e);

/* Fills *d with Davis's defaults (St_n 2, Ca 1000, h_a 0.01, h_m 0.01, beta 30 deg,
 * d_23 = d_13 = 1, h_23,0 = 1, theta_23,0 = 0, e_dry 1, mu_f 0, t* 20). */
WETDEM_API void wetdem_pairwise_davis_init(struct wetdem_pairwise_davis* d);
/* Descriptors of struct wetdem_pairwise_davis ("stokes", "capillary", "film_ratio",
 * "hmin_ratio", "angle_deg", "d23", "d13", "h23", "theta23_deg", "restitution", "friction",
 * ...), {0}-terminated, for scenario files and sweeps. */
WETDEM_API const struct wetdem_param_desc* wetdem_pairwise_davis_params(void);
/* Builds the Table-I configuration (Fig. 3): sphere 0 (Davis's 1) strikes sphere 1 (2) at
 * angle beta with films just touching; sphere 2 (3) rests at gap h_23,0 and angle
 * theta_23,0 from sphere 1. Returns WETDEM_OK or WETDEM_ERR_INVALID (message in msg). */
WETDEM_API int wetdem_pairwise_davis_config(const struct wetdem_pairwise_davis* d,
                                            struct wetdem_pairwise_config* cfg, char* msg,
                                            size_t msg_size);

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
    double fps;        /* frame rate [1/s] > 0 (Punch: 5000) */
    double pixel_size; /* image resolution [m/pixel] > 0 (Punch: 175e-6) */
    bool y_down;       /* the y pixel axis points down (image rows): y is negated on input so
                            that (x, y) is right-handed and omega > 0 is counter-clockwise on
                            screen (default false) */
    int window;        /* Savitzky-Golay window [frames], odd, > order (7); 1: no smoothing */
    int order;         /* Savitzky-Golay polynomial order, >= 0, < window (2) */
    double threshold;  /* collision: striker velocity change [m/s] > 0 (0.05) */
    int offset;        /* frames before/after the collision frame where the velocities are
                            taken (5), >= 1 */
    int fit_frames;    /* frame intervals in each straight-line fit, >= 3; 0: all (0) */
    int striker;       /* sphere id of the striker; -1: the faster sphere at the start (-1) */
    double radius;     /* sphere radius [m] for St_n; 0: not given (no St_n) */
    double mass;       /* sphere mass [kg] for St_n; 0: not given */
    double viscosity;  /* film viscosity [Pa s] for St_n; 0: not given */
};

/* Velocity of one sphere over the frame interval frame -> frame + 1 (Punch Eq. 23). */
struct wetdem_track_sample {
    long frame;                       /* first frame of the interval */
    double time;                      /* interval midpoint (frame + 1/2)/fps [s] */
    double vx_raw, vy_raw, omega_raw; /* from the unsmoothed dots [m/s], [rad/s] */
    double vx, vy, omega;             /* from the Savitzky-Golay smoothed dots */
    double residual;                  /* rms residual of Eq. 23 on the smoothed dots [m] */
    /* standard uncertainties (1 sigma) of the six velocities above from the tracking noise
     * (docs/tracking.md "Uncertainties"), in their units */
    double u_vx_raw, u_vy_raw, u_omega_raw;
    double u_vx, u_vy, u_omega;
};

/* Velocities and dot-1 position of one sphere at one frame (straight-line fit values); also
 * their standard uncertainties (the u_ fields of struct wetdem_track_summary). */
struct wetdem_track_state {
    double vx, vy; /* [m/s] */
    double omega;  /* spin about the camera axis, counter-clockwise in (x, y) [rad/s] */
    double x, y;   /* smoothed position of dot 1 (the centre) [m] */
};

/* The collision found in a two-sphere track. */
struct wetdem_track_summary {
    size_t n_spheres; /* 1 or 2; the fields below need 2 */
    bool has_collision;
    int striker_id, target_id; /* sphere ids as in the input */
    long collision_frame;      /* last frame before the striker's velocity changes */
    double collision_time;     /* collision_frame / fps [s] */
    struct wetdem_track_state striker_before, striker_after; /* at collision_frame -/+ offset */
    struct wetdem_track_state target_before, target_after;
    double angle_centres;      /* Eq. 16: atan of dy/dx of the centres at the collision
                                        frame [rad], in (-pi/2, pi/2] */
    double impact_angle;       /* angle between the relative velocity before and the
                                        line of centres at the collision frame [rad] */
    double speed_n0, speed_nf; /* normal relative speed before (approach > 0) and after
                                        (separation > 0) [m/s] */
    double e_n;                /* Eq. 3: speed_nf / speed_n0 [-] */
    double stokes_n;           /* Eq. 2 with m* = m/2, R* = R/2; NAN without options */
    /* Tracking noise per pixel coordinate estimated from the residuals of Eq. 23 on the raw
     * dots, per sphere in the order of wetdem_track_sphere_id() [pixel]; also with one
     * sphere (noise_px[1] then NAN). */
    double noise_px[2];
    /* Standard uncertainties (1 sigma) of the values above from that noise, propagated to
     * first order with their correlations (docs/tracking.md "Uncertainties"); in the same
     * units; NAN where the value is NAN. Systematic biases are not included. */
    struct wetdem_track_state u_striker_before, u_striker_after;
    struct wetdem_track_state u_target_before, u_target_after;
    double u_angle_centres, u_impact_angle; /* [rad] */
    double u_speed_n0, u_speed_nf;          /* [m/s] */
    double u_e_n, u_stokes_n;               /* [-] */
};

/* Allocates an empty track. NULL only if out of memory. */
WETDEM_API struct wetdem_track* wetdem_track_create(void);
/* Frees a track and its results. NULL does nothing. */
WETDEM_API void wetdem_track_free(struct wetdem_track* track);
/* Last detailed error message of this track ("" if none). */
WETDEM_API const char* wetdem_track_errmsg(const struct wetdem_track* track);
/* Appends one frame of sphere `sphere_id` (>= 0; at most two spheres): xy = x1,y1,x2,y2,x3,y3
 * [pixel]. Frames of a sphere must follow one another without gaps; |frame| <= 1e12. Returns
 * WETDEM_OK, WETDEM_ERR_INVALID (NaN, gap, non-increasing or out-of-range frame, third sphere)
 * or WETDEM_ERR_NOMEM. */
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

/* A least-squares problem: minimise sum_i ((predicted_i - observed_i)/scale_i)^2 over the
 * parameters, each kept inside its range [lower_j, upper_j] by the variable the solver varies
 * (src/fit.c, docs/calibration.md "Method"): q = p without bounds, q = ln(p - lower) with a
 * lower bound only, q = ln(upper - p) with an upper bound only, and the logistic
 * q = ln((p - lower)/(upper - p)) with both; so every evaluation of the model, the
 * finite-difference probes included, lies strictly inside the range. */
struct wetdem_fit_problem {
    size_t n_params;          /* 1..WETDEM_FIT_MAX_PARAMS */
    const char* const* names; /* parameter names for messages (may be NULL) */
    const double* initial;    /* initial values [n_params], strictly inside a finite bound */
    const bool* is_log;       /* per parameter: a lower bound of (at least) 0, so p stays > 0
                                 and steps are relative; NULL: for initial > 0 when lower and
                                 upper are both NULL */
    size_t n_data;            /* > n_params (the residual variance needs a degree of freedom) */
    const double* observed;   /* [n_data] */
    const double* scale;      /* [n_data] divisor of each residual (finite, > 0), NULL: all 1 */
    wetdem_fit_model_fn model;
    void* ctx;
    const double* lower; /* [n_params] lower bounds (-INFINITY: none); NULL: none */
    const double* upper; /* [n_params] upper bounds (INFINITY: none); NULL: none */
};

/* Options of wetdem_fit_run(): max_iter >= 1, tolerances finite and > 0, fd_step in (0, 1). */
struct wetdem_fit_options {
    int max_iter;   /* trust-region iterations (50) */
    double xtol;    /* step tolerance, relative in the fitted variables (1e-6) */
    double gtol;    /* gradient tolerance (1e-8) */
    double ftol;    /* cost-reduction tolerance (1e-10) */
    double fd_step; /* central-difference step of the Jacobian in the fitted variable q: a
                        relative change of the distance to a bound for bounded parameters,
                        absolute x max(|p|, 1) for unbounded ones (1e-2: larger than the
                        integration noise of simulated predictions) */
};

/* How a parameter is varied (wetdem_fit_result.transform). */
enum wetdem_fit_transform {
    WETDEM_FIT_LINEAR = 0,    /* q = p (no bound) */
    WETDEM_FIT_LOG_LOWER = 1, /* q = ln(p - lower) (a lower bound only; ln p for lower = 0) */
    WETDEM_FIT_LOG_UPPER = 2, /* q = ln(upper - p) (an upper bound only) */
    WETDEM_FIT_LOGISTIC = 3,  /* q = ln((p - lower)/(upper - p)) (both bounds) */
};

struct wetdem_fit_result {
    double values[WETDEM_FIT_MAX_PARAMS];     /* best-fit parameters */
    double std_errors[WETDEM_FIT_MAX_PARAMS]; /* standard errors: sqrt(diag((J^T J)^-1)) s in
                                                 the fitted variable, s^2 = cost/dof, mapped to
                                                 p by dp = (dp/dq) dq; INFINITY for a
                                                 parameter the data do not determine, NAN for
                                                 one at a bound */
    double correlation[WETDEM_FIT_MAX_PARAMS][WETDEM_FIT_MAX_PARAMS]; /* of the estimates (NAN
                                                 in the rows of the two kinds above) */
    double cost;         /* sum of squared scaled residuals at the solution */
    double residual_std; /* s = sqrt(cost/dof), in units of the scale */
    size_t dof;          /* n_data - n_params; 0 when the fit stopped before a solution */
    size_t iterations;
    size_t model_evals; /* calls of the model function (the flat-start probes included) */
    int converged_by;   /* 1 small step (xtol), 2 small gradient (gtol), 3 small cost change;
                           0 not converged */
    int transform[WETDEM_FIT_MAX_PARAMS];     /* enum wetdem_fit_transform of each parameter */
    int at_bound[WETDEM_FIT_MAX_PARAMS];      /* -1 at its lower bound, +1 at its upper bound:
                                             closer to it than its standard error (the data do
                                             not tell it from the bound) and than 1e-3 of its
                                             initial distance (the fit ran towards it);
                                             its standard error is then NAN and the others'
                                             are those with it held there; 0 inside */
    bool undetermined[WETDEM_FIT_MAX_PARAMS]; /* the data do not determine it: its column of
                                                 the Jacobian is zero, or a combination of
                                                 columns is; or a flat start (a bounded
                                                 parameter that ended within a factor 10 of its
                                                 start, where a factor 1000 either way in its
                                                 distance to the bound, or in (p - lower)/
                                                 (upper - p) with two bounds, moves the
                                                 residuals by less than 0.1 of their scatter s,
                                                 by its column and by two evaluations of the
                                                 model; an unbounded parameter has no such
                                                 scale: only its zero column counts):
                                                 WETDEM_ERR_UNDETERMINED */
};

/* Fills *opt with the defaults above. */
WETDEM_API void wetdem_fit_options_init(struct wetdem_fit_options* opt);
/* Solves the problem with the GSL trust-region (Levenberg-Marquardt) solver and a
 * central-difference Jacobian. predicted (may be NULL) receives the predictions at the
 * solution [n_data]; opt NULL takes the defaults of wetdem_fit_options_init(). Returns
 * WETDEM_OK (a parameter at a bound is reported in *result, not as an error),
 * WETDEM_ERR_INVALID (bad problem or options, problem or result NULL, an initial value not
 * finite, or outside or on a bound), WETDEM_ERR_CALLBACK or the model's status (the model failed), WETDEM_ERR_MAX_STEPS
 * (not converged; *result holds the last iterate), WETDEM_ERR_UNDETERMINED (the data do not
 * depend on a parameter, exactly or beyond their scatter where the fit stopped, e.g. at a start
 * where its effect is cut off (see undetermined above), or do not determine some parameters
 * separately: *result holds the last iterate with those parameters' standard errors INFINITY),
 * WETDEM_ERR_STEP (the solver found no step that lowers the cost) or WETDEM_ERR_NOMEM; msg (may
 * be NULL) receives a message. A flat-start probe the model fails on is no failure of the fit
 * (it only means the parameter is not flat). GSL's error handler is switched off while the
 * call runs, so a GSL error never aborts the program, and the caller's handler is restored when
 * the call returns, or with fits running at once in several threads, when the last of them
 * returns; GSL keeps that handler in one process-wide variable, so do not change it, or rely on
 * GSL's default handler, in another thread while a fit runs. */
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
