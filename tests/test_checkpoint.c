/*
 * test_checkpoint.c — binary checkpoints (src/checkpoint.c): exact round trip of every field,
 * RNG continuation, byte-identical files for equal states, detection of corruption,
 * truncation, foreign files, other versions and byte orders, atomic replacement, and the
 * CRC-32 / FNV-1a reference values.
 */
#include <stdlib.h>
#include <sys/stat.h>
#include <unistd.h>

#include "checkpoint.h"
#include "harness.h"
#include "vec3.h"

#define NP 50
#define NW 3
#define NPAIR 17
#define HLEN 5
#define NE 4

struct fixture {
    struct wetdem_particle particles[NP];
    struct wetdem_checkpoint_wall walls[NW];
    struct wetdem_checkpoint_pair pairs[NPAIR];
    double history[NPAIR * HLEN];
    double energy[NE];
    unsigned char extra[11];
    gsl_rng* rng;
    struct wetdem_checkpoint ck;
    char path[64];
};

static int setup(void** state)
{
    struct fixture* f = calloc(1, sizeof *f);
    f->rng = gsl_rng_alloc(gsl_rng_mt19937);
    gsl_rng_set(f->rng, 2024);
    for (size_t k = 0; k < NP; k++) /* awkward doubles: every bit must survive */
        f->particles[k] = (struct wetdem_particle){
            .pos = vec3(gsl_rng_uniform(f->rng), 1.0 / 3.0 + k, -1e-300 * k),
            .vel = vec3(M_PI * k, -0.0, 1e300),
            .omega = vec3(gsl_rng_uniform(f->rng), NAN, INFINITY),
            .radius = 1e-3 + k * 1e-6,
            .mass = 4e-6 / (k + 1),
            .material = (int)k % 4,
            .is_fixed = k % 7 == 0};
    for (size_t k = 0; k < NW; k++)
        f->walls[k] = (struct wetdem_checkpoint_wall){vec3(0, 0, 0.1 * k), vec3(0, 0, 1), 1};
    for (size_t k = 0; k < NPAIR; k++)
        f->pairs[k] = (struct wetdem_checkpoint_pair){k, (k * 13) % NP, k % 5 == 0};
    for (size_t k = 0; k < NPAIR * HLEN; k++)
        f->history[k] = gsl_rng_uniform(f->rng) - 0.5;
    for (size_t k = 0; k < NE; k++)
        f->energy[k] = 1e-7 * (k + 1) / 3;
    memcpy(f->extra, "hello\0world", 11);
    f->ck = (struct wetdem_checkpoint){.time = 0.1 + 0.2,
                                       .step = 123456789012ull,
                                       .config_hash = 0xdeadbeefcafef00dull,
                                       .particles = f->particles,
                                       .n_particles = NP,
                                       .walls = f->walls,
                                       .n_walls = NW,
                                       .pairs = f->pairs,
                                       .history = f->history,
                                       .n_pairs = NPAIR,
                                       .history_len = HLEN,
                                       .stats = {.steps = 1,
                                                 .rejected_steps = 2,
                                                 .force_evals = 3,
                                                 .pair_evals = 4,
                                                 .root_evals = 5,
                                                 .events = 6},
                                       .output = {7, 8, 9, 10},
                                       .energy = f->energy,
                                       .n_energy = NE,
                                       .extra = f->extra,
                                       .extra_size = sizeof f->extra};
    CHECK_OK(wetdem_checkpoint_save_rng(&f->ck, f->rng));
    strcpy(f->path, "/tmp/wetdem_test_ckpt_XXXXXX");
    int fd = mkstemp(f->path);
    close(fd);
    *state = f;
    return 0;
}

static int teardown(void** state)
{
    struct fixture* f = *state;
    free(f->ck.rng_state);
    gsl_rng_free(f->rng);
    remove(f->path);
    free(f);
    return 0;
}

#define SAME_BITS(a, b) assert_memory_equal(&(a), &(b), sizeof(a))

static void check_particle(const struct wetdem_particle* a, const struct wetdem_particle* b)
{
    SAME_BITS(a->pos, b->pos);
    SAME_BITS(a->vel, b->vel);
    SAME_BITS(a->omega, b->omega);
    SAME_BITS(a->radius, b->radius);
    SAME_BITS(a->mass, b->mass);
    assert_int_equal(a->material, b->material);
    assert_int_equal(a->is_fixed, b->is_fixed);
}

static void test_checkpoint_round_trip_is_exact(void** state)
{
    struct fixture* f = *state;
    char msg[256] = "";
    CHECK_OK(wetdem_checkpoint_write(f->path, &f->ck, msg, sizeof msg));
    struct wetdem_checkpoint r;
    CHECK_OK(wetdem_checkpoint_read(f->path, &r, msg, sizeof msg));
    SAME_BITS(r.time, f->ck.time);
    assert_true(r.step == f->ck.step && r.config_hash == f->ck.config_hash);
    assert_int_equal(r.n_particles, NP);
    for (size_t k = 0; k < NP; k++)
        check_particle(&r.particles[k], &f->particles[k]);
    assert_int_equal(r.n_walls, NW);
    for (size_t k = 0; k < NW; k++) {
        SAME_BITS(r.walls[k].point, f->walls[k].point);
        SAME_BITS(r.walls[k].normal, f->walls[k].normal);
        assert_int_equal(r.walls[k].material, f->walls[k].material);
    }
    assert_int_equal(r.n_pairs, NPAIR);
    assert_int_equal(r.history_len, HLEN);
    for (size_t k = 0; k < NPAIR; k++)
        assert_true(r.pairs[k].i == f->pairs[k].i && r.pairs[k].j == f->pairs[k].j &&
                    r.pairs[k].is_wall == f->pairs[k].is_wall);
    assert_memory_equal(r.history, f->history, sizeof f->history);
    assert_memory_equal(r.energy, f->energy, sizeof f->energy);
    assert_int_equal(r.extra_size, sizeof f->extra);
    assert_memory_equal(r.extra, f->extra, sizeof f->extra);
    assert_memory_equal(&r.stats, &f->ck.stats, sizeof r.stats);
    assert_memory_equal(&r.output, &f->ck.output, sizeof r.output);
    assert_string_equal(r.rng_name, "mt19937");
    wetdem_checkpoint_clear(&r);
    assert_null(r.particles);
}

static void test_checkpoint_restored_rng_continues_the_sequence(void** state)
{
    struct fixture* f = *state;
    CHECK_OK(wetdem_checkpoint_write(f->path, &f->ck, NULL, 0));
    double want[10];
    for (int k = 0; k < 10; k++)
        want[k] = gsl_rng_uniform(f->rng); /* the original generator continues */
    struct wetdem_checkpoint r;
    CHECK_OK(wetdem_checkpoint_read(f->path, &r, NULL, 0));
    gsl_rng* g = gsl_rng_alloc(gsl_rng_mt19937);
    gsl_rng_set(g, 1); /* different state before restoring */
    CHECK_OK(wetdem_checkpoint_restore_rng(&r, g, NULL, 0));
    for (int k = 0; k < 10; k++)
        assert_true(gsl_rng_uniform(g) == want[k]);
    gsl_rng* other = gsl_rng_alloc(gsl_rng_ranlxd2);
    char msg[256] = "";
    CHECK_STATUS(wetdem_checkpoint_restore_rng(&r, other, msg, sizeof msg), WETDEM_ERR_INVALID);
    CHECK_CONTAINS(msg, "mt19937");
    gsl_rng_free(other);
    gsl_rng_free(g);
    wetdem_checkpoint_clear(&r);
}

static unsigned char* file_bytes(const char* path, size_t* len)
{
    FILE* fp = fopen(path, "rb");
    fseek(fp, 0, SEEK_END);
    *len = (size_t)ftell(fp);
    fseek(fp, 0, SEEK_SET);
    unsigned char* d = malloc(*len);
    assert_int_equal(fread(d, 1, *len, fp), *len);
    fclose(fp);
    return d;
}

static void put_file(const char* path, const unsigned char* d, size_t len)
{
    FILE* fp = fopen(path, "wb");
    fwrite(d, 1, len, fp);
    fclose(fp);
}

static void test_checkpoint_equal_states_give_identical_files(void** state)
{
    struct fixture* f = *state;
    size_t la, lb;
    CHECK_OK(wetdem_checkpoint_write(f->path, &f->ck, NULL, 0));
    unsigned char* a = file_bytes(f->path, &la);
    CHECK_OK(wetdem_checkpoint_write(f->path, &f->ck, NULL, 0));
    unsigned char* b = file_bytes(f->path, &lb);
    assert_int_equal(la, lb);
    assert_memory_equal(a, b, la);
    /* size by hand: header 24 + 7 section headers x 16 + META 144 + 50 x 96 + 3 x 56
     * + 17 x (24 + 5 x 8) + RNG (32 + state) + 4 x 8 + 11 + CRC 4 */
    size_t want = 24 + 7 * 16 + 144 + NP * 96 + NW * 56 + NPAIR * (24 + HLEN * 8) +
                  (32 + f->ck.rng_size) + NE * 8 + 11 + 4;
    assert_int_equal(la, want);
    free(a);
    free(b);
}

/* Rewrites the CRC so that a deliberate header change is seen by the header checks. */
static void fix_crc(unsigned char* d, size_t len)
{
    uint32_t crc = wetdem_checkpoint_crc32(0, d, len - 4);
    memcpy(d + len - 4, &crc, 4);
}

static void expect_parse_error(const char* path, const char* needle)
{
    struct wetdem_checkpoint r;
    char msg[256] = "";
    CHECK_STATUS(wetdem_checkpoint_read(path, &r, msg, sizeof msg), WETDEM_ERR_PARSE);
    CHECK_CONTAINS(msg, needle);
    assert_null(r.particles);
}

static void test_checkpoint_detects_damage(void** state)
{
    struct fixture* f = *state;
    CHECK_OK(wetdem_checkpoint_write(f->path, &f->ck, NULL, 0));
    size_t len;
    unsigned char* d = file_bytes(f->path, &len);
    d[len / 2] ^= 0x10; /* one flipped bit in the particle data */
    put_file(f->path, d, len);
    expect_parse_error(f->path, "CRC mismatch");
    d[len / 2] ^= 0x10;
    put_file(f->path, d, len - 100); /* truncated */
    expect_parse_error(f->path, "CRC mismatch");
    unsigned char* e = malloc(len);
    memcpy(e, d, len);
    e[12] ^= 0xff; /* byte-order marker */
    fix_crc(e, len);
    put_file(f->path, e, len);
    expect_parse_error(f->path, "other byte order");
    memcpy(e, d, len);
    e[8] = 9; /* version 9 */
    fix_crc(e, len);
    put_file(f->path, e, len);
    expect_parse_error(f->path, "format version 9");
    memcpy(e, d, len);
    uint64_t huge = 1ull << 40; /* n_particles in META no longer matches the PART payload */
    memcpy(e + 24 + 16 + 24, &huge, 8);
    fix_crc(e, len);
    put_file(f->path, e, len);
    expect_parse_error(f->path, "malformed");
    put_file(f->path, (const unsigned char*)"# vtk DataFile Version 3.0\n", 27);
    expect_parse_error(f->path, "not a wetdem checkpoint");
    free(e);
    free(d);
}

/* A path that cannot be read is an I/O error that says why: a directory (it opens for reading
 * on Linux, and its size read as an allocation of unknown size, WETDEM_ERR_NOMEM, without a
 * reason) and a missing file. */
static void test_checkpoint_unreadable_path_says_why(void** state)
{
    (void)state;
    struct wetdem_checkpoint ck;
    char msg[256] = "";
    assert_int_equal(wetdem_checkpoint_read("/tmp", &ck, msg, sizeof msg), WETDEM_ERR_IO);
    CHECK_CONTAINS(msg, "cannot read checkpoint '/tmp': Is a directory");
    assert_int_equal(wetdem_checkpoint_read("/nonexistent/ck.bin", &ck, msg, sizeof msg),
                     WETDEM_ERR_IO);
    CHECK_CONTAINS(msg, "No such file or directory");
}

static void test_checkpoint_failed_write_keeps_the_old_file(void** state)
{
    struct fixture* f = *state;
    CHECK_OK(wetdem_checkpoint_write(f->path, &f->ck, NULL, 0));
    char tmp[80];
    snprintf(tmp, sizeof tmp, "%s.tmp", f->path);
    assert_int_equal(access(tmp, F_OK), -1); /* renamed away after success */
    assert_int_equal(mkdir(tmp, 0700), 0);   /* now the temporary cannot be created */
    f->ck.time = 99;
    char msg[256] = "";
    CHECK_STATUS(wetdem_checkpoint_write(f->path, &f->ck, msg, sizeof msg), WETDEM_ERR_IO);
    CHECK_CONTAINS(msg, tmp);
    rmdir(tmp);
    struct wetdem_checkpoint r;
    CHECK_OK(wetdem_checkpoint_read(f->path, &r, NULL, 0));
    CHECK_ABS(r.time, 0.1 + 0.2, 0); /* the old checkpoint, untouched */
    wetdem_checkpoint_clear(&r);
    CHECK_STATUS(wetdem_checkpoint_read("/nonexistent/ck.bin", &r, msg, sizeof msg), WETDEM_ERR_IO);
    CHECK_CONTAINS(msg, "/nonexistent/ck.bin");
}

static void test_checkpoint_empty_run_round_trips(void** state)
{
    struct fixture* f = *state;
    struct wetdem_checkpoint e = {.time = 1.5}, r;
    CHECK_OK(wetdem_checkpoint_write(f->path, &e, NULL, 0));
    CHECK_OK(wetdem_checkpoint_read(f->path, &r, NULL, 0));
    assert_int_equal(r.n_particles, 0);
    assert_int_equal(r.n_pairs, 0);
    assert_string_equal(r.rng_name, "");
    CHECK_ABS(r.time, 1.5, 0); /* stored as its bytes: exact */
    wetdem_checkpoint_clear(&r);
}

/* A run's checkpoint_note (the names of the CLI's outputs) comes back as written, in a NOTE
 * section of a 16-byte header and its text; none leaves the file as it was without notes
 * (older readers skip the section: tag, flags, size). */
static void test_checkpoint_note_round_trips(void** state)
{
    struct fixture* f = *state;
    struct wetdem_checkpoint r;
    struct stat plain, noted;
    CHECK_OK(wetdem_checkpoint_write(f->path, &f->ck, NULL, 0));
    assert_int_equal(stat(f->path, &plain), 0);
    CHECK_OK(wetdem_checkpoint_read(f->path, &r, NULL, 0));
    assert_null(r.note);
    wetdem_checkpoint_clear(&r);
    const char* note = "vtk = particles\ncsv = global.csv";
    f->ck.note = (char*)note;
    CHECK_OK(wetdem_checkpoint_write(f->path, &f->ck, NULL, 0));
    f->ck.note = NULL;
    assert_int_equal(stat(f->path, &noted), 0);
    assert_int_equal(noted.st_size - plain.st_size, 16 + (off_t)strlen(note));
    CHECK_OK(wetdem_checkpoint_read(f->path, &r, NULL, 0));
    assert_non_null(r.note);
    assert_string_equal(r.note, note);
    wetdem_checkpoint_clear(&r);
    assert_null(r.note);
}

/* Standard check values: CRC-32/ISO-HDLC of "123456789" is 0xCBF43926; FNV-1a 64 of "a" is
 * 0xaf63dc4c8601ec8c (Fowler-Noll-Vo reference test vectors). */
static void test_checkpoint_checksums_match_reference_values(void** state)
{
    (void)state;
    assert_int_equal(wetdem_checkpoint_crc32(0, "123456789", 9), 0xCBF43926u);
    /* continuing a CRC gives the CRC of the concatenation */
    assert_int_equal(wetdem_checkpoint_crc32(wetdem_checkpoint_crc32(0, "1234", 4), "56789", 5),
                     0xCBF43926u);
    assert_true(wetdem_checkpoint_hash(0, "a", 1) == 0xaf63dc4c8601ec8cull);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_checkpoint_unreadable_path_says_why),
        cmocka_unit_test_setup_teardown(test_checkpoint_round_trip_is_exact, setup, teardown),
        cmocka_unit_test_setup_teardown(test_checkpoint_restored_rng_continues_the_sequence, setup,
                                        teardown),
        cmocka_unit_test_setup_teardown(test_checkpoint_equal_states_give_identical_files, setup,
                                        teardown),
        cmocka_unit_test_setup_teardown(test_checkpoint_detects_damage, setup, teardown),
        cmocka_unit_test_setup_teardown(test_checkpoint_failed_write_keeps_the_old_file, setup,
                                        teardown),
        cmocka_unit_test_setup_teardown(test_checkpoint_empty_run_round_trips, setup, teardown),
        cmocka_unit_test_setup_teardown(test_checkpoint_note_round_trips, setup, teardown),
        cmocka_unit_test(test_checkpoint_checksums_match_reference_values),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
