/*
 * checkpoint.c — binary checkpoint writer and reader for many-particle runs. Prefix:
 * wetdem_checkpoint.
 *
 * File layout (version 1; all integers and doubles in the writer's byte order, which the
 * endianness marker records; doubles are IEEE 754 binary64 stored bit for bit, so a resumed
 * run continues from exactly the same state):
 *
 *   header   "WETDEMCK" | u32 version = 1 | u32 0x01020304 | u32 n_sections | u32 0
 *   section  char tag[4] | u32 flags = 0 | u64 payload bytes | payload
 *     META   f64 time | u64 step | u64 config_hash | u64 n_particles | u64 n_walls
 *            | u64 n_pairs | u64 history_len | u64 n_energy | u64 stats[6] | u64 output[4]
 *     PART   n_particles x (f64 pos[3], vel[3], omega[3], radius, mass | i32 material
 *            | u8 is_fixed | 3 zero bytes)                                     96 bytes each
 *     WALL   n_walls x (f64 point[3], normal[3] | i32 material | 4 zero bytes) 56 bytes each
 *     PAIR   n_pairs x (u64 i | u64 j | u8 is_wall | 7 zero bytes) then n_pairs x
 *            history_len f64, keys sorted as the engine stores them
 *     RNG_   char name[32] | state bytes (gsl_rng_state, gsl_rng_size bytes)
 *     ENER   n_energy f64 energy-budget accumulators [J]
 *     USER   opaque bytes
 *     NOTE   the run's checkpoint_note, text without its NUL (only when it has one)
 *   trailer  u32 CRC-32 of every byte before it
 *
 * Records are written field by field (never whole structs), so padding never reaches the file
 * and equal states give byte-identical files. META comes first; readers skip sections with
 * unknown tags, so later versions can add sections without breaking old readers; a change to
 * an existing section bumps the version.
 */
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "checkpoint.h"
#include "status.h"

#define MAGIC "WETDEMCK"
#define ENDIAN_MARK 0x01020304u
#define HEADER_BYTES 24
#define META_BYTES 144
#define PART_BYTES 96
#define WALL_BYTES 56
#define KEY_BYTES 24

/* CRC-32 with a 16-entry table (half a byte per step): small and fast enough for files of a
 * few hundred MB. table[k] = CRC of the 4-bit value k. */
uint32_t wetdem_checkpoint_crc32(uint32_t crc, const void* data, size_t n)
{
    static const uint32_t table[16] = {0x00000000u, 0x1db71064u, 0x3b6e20c8u, 0x26d930acu,
                                       0x76dc4190u, 0x6b6b51f4u, 0x4db26158u, 0x5005713cu,
                                       0xedb88320u, 0xf00f9344u, 0xd6d6a3e8u, 0xcb61b38cu,
                                       0x9b64c2b0u, 0x86d3d2d4u, 0xa00ae278u, 0xbdbdf21cu};
    const unsigned char* p = data;
    crc = ~crc;
    for (size_t k = 0; k < n; k++) {
        crc ^= p[k];
        crc = (crc >> 4) ^ table[crc & 15];
        crc = (crc >> 4) ^ table[crc & 15];
    }
    return ~crc;
}

uint64_t wetdem_checkpoint_hash(uint64_t h, const void* data, size_t n)
{
    const unsigned char* p = data;
    if (h == 0)
        h = 0xcbf29ce484222325ull; /* FNV offset basis */
    for (size_t k = 0; k < n; k++) {
        h ^= p[k];
        h *= 0x100000001b3ull; /* FNV prime */
    }
    return h;
}

/* ---- writing into a growing buffer ---- */

struct buf {
    unsigned char* data;
    size_t len, cap;
    bool nomem;
};

static void put(struct buf* b, const void* x, size_t n)
{
    if (b->nomem)
        return;
    if (b->len + n > b->cap) {
        size_t cap = b->cap ? b->cap : 4096;
        while (cap < b->len + n)
            cap *= 2;
        unsigned char* d = realloc(b->data, cap);
        if (!d) {
            b->nomem = true;
            return;
        }
        b->data = d;
        b->cap = cap;
    }
    memcpy(b->data + b->len, x, n);
    b->len += n;
}

static void put_u64(struct buf* b, uint64_t x)
{
    put(b, &x, 8);
}
static void put_u32(struct buf* b, uint32_t x)
{
    put(b, &x, 4);
}
static void put_i32(struct buf* b, int32_t x)
{
    put(b, &x, 4);
}
static void put_f64(struct buf* b, double x)
{
    put(b, &x, 8);
}
static void put_vec(struct buf* b, struct wetdem_vec3 v)
{
    put_f64(b, v.x);
    put_f64(b, v.y);
    put_f64(b, v.z);
}
static void put_zeros(struct buf* b, size_t n)
{
    static const unsigned char z[8] = {0};
    put(b, z, n);
}

/* Writes a section header with the payload size. */
static void put_section(struct buf* b, const char tag[4], uint64_t bytes, uint32_t* n_sections)
{
    put(b, tag, 4);
    put_u32(b, 0);
    put_u64(b, bytes);
    (*n_sections)++;
}

static void put_meta(struct buf* b, const struct wetdem_checkpoint* ck, uint32_t* ns)
{
    put_section(b, "META", META_BYTES, ns);
    put_f64(b, ck->time);
    put_u64(b, ck->step);
    put_u64(b, ck->config_hash);
    uint64_t counts[5] = {ck->n_particles, ck->n_walls, ck->n_pairs, ck->history_len, ck->n_energy};
    put(b, counts, sizeof counts);
    const struct wetdem_stats* s = &ck->stats;
    uint64_t stats[6] = {s->steps,      s->rejected_steps, s->force_evals,
                         s->pair_evals, s->root_evals,     s->events};
    put(b, stats, sizeof stats);
    const struct wetdem_checkpoint_output* o = &ck->output;
    uint64_t out[4] = {o->vtk_files, o->csv_rows, o->next_vtk_step, o->next_csv_step};
    put(b, out, sizeof out);
}

static void put_bodies(struct buf* b, const struct wetdem_checkpoint* ck, uint32_t* ns)
{
    put_section(b, "PART", (uint64_t)ck->n_particles * PART_BYTES, ns);
    for (size_t k = 0; k < ck->n_particles; k++) {
        const struct wetdem_particle* p = &ck->particles[k];
        put_vec(b, p->pos);
        put_vec(b, p->vel);
        put_vec(b, p->omega);
        put_f64(b, p->radius);
        put_f64(b, p->mass);
        put_i32(b, p->material);
        unsigned char fixed = p->is_fixed ? 1 : 0;
        put(b, &fixed, 1);
        put_zeros(b, 3);
    }
    put_section(b, "WALL", (uint64_t)ck->n_walls * WALL_BYTES, ns);
    for (size_t k = 0; k < ck->n_walls; k++) {
        put_vec(b, ck->walls[k].point);
        put_vec(b, ck->walls[k].normal);
        put_i32(b, ck->walls[k].material);
        put_zeros(b, 4);
    }
}

static void put_rest(struct buf* b, const struct wetdem_checkpoint* ck, uint32_t* ns)
{
    uint64_t hist = (uint64_t)ck->n_pairs * ck->history_len;
    put_section(b, "PAIR", (uint64_t)ck->n_pairs * KEY_BYTES + 8 * hist, ns);
    for (size_t k = 0; k < ck->n_pairs; k++) {
        put_u64(b, ck->pairs[k].i);
        put_u64(b, ck->pairs[k].j);
        unsigned char w = ck->pairs[k].is_wall ? 1 : 0;
        put(b, &w, 1);
        put_zeros(b, 7);
    }
    if (hist)
        put(b, ck->history, 8 * hist);
    char name[WETDEM_CHECKPOINT_RNG_NAME] = {0};
    memcpy(name, ck->rng_name, strnlen(ck->rng_name, sizeof name - 1));
    put_section(b, "RNG_", sizeof name + ck->rng_size, ns);
    put(b, name, sizeof name);
    if (ck->rng_size)
        put(b, ck->rng_state, ck->rng_size);
    put_section(b, "ENER", 8 * (uint64_t)ck->n_energy, ns);
    if (ck->n_energy)
        put(b, ck->energy, 8 * ck->n_energy);
    put_section(b, "USER", ck->extra_size, ns);
    if (ck->extra_size)
        put(b, ck->extra, ck->extra_size);
    if (ck->note && ck->note[0]) { /* (none: the file is as without notes) */
        put_section(b, "NOTE", strlen(ck->note), ns);
        put(b, ck->note, strlen(ck->note));
    }
}

static int write_file(const char* path, const struct buf* b, char* msg, size_t n)
{
    char tmp[4096];
    if ((size_t)snprintf(tmp, sizeof tmp, "%s.tmp", path) >= sizeof tmp)
        return wetdem_status_fail(msg, n, WETDEM_ERR_IO, "checkpoint path too long: '%s'", path);
    FILE* f = fopen(tmp, "wb");
    if (!f)
        return wetdem_status_fail(msg, n, WETDEM_ERR_IO, "cannot open '%s' for writing: %s", tmp,
                                  strerror(errno));
    bool ok = fwrite(b->data, 1, b->len, f) == b->len && fflush(f) == 0 && fsync(fileno(f)) == 0;
    int err = errno;
    ok = (fclose(f) == 0) && ok;
    if (!ok || rename(tmp, path) != 0) {
        err = ok ? errno : err;
        remove(tmp);
        return wetdem_status_fail(msg, n, WETDEM_ERR_IO, "cannot write checkpoint '%s': %s", path,
                                  strerror(err));
    }
    return WETDEM_OK;
}

int wetdem_checkpoint_write(const char* path, const struct wetdem_checkpoint* ck, char* msg,
                            size_t msg_size)
{
    struct buf b = {0};
    uint32_t n_sections = 0;
    put(&b, MAGIC, 8);
    put_u32(&b, WETDEM_CHECKPOINT_VERSION);
    put_u32(&b, ENDIAN_MARK);
    put_u32(&b, 0); /* n_sections, patched below */
    put_u32(&b, 0);
    put_meta(&b, ck, &n_sections);
    put_bodies(&b, ck, &n_sections);
    put_rest(&b, ck, &n_sections);
    if (!b.nomem) {
        memcpy(b.data + 16, &n_sections, 4);
        put_u32(&b, wetdem_checkpoint_crc32(0, b.data, b.len));
    }
    int st = b.nomem ? wetdem_status_fail(msg, msg_size, WETDEM_ERR_NOMEM,
                                          "out of memory writing checkpoint '%s'", path)
                     : write_file(path, &b, msg, msg_size);
    free(b.data);
    return st;
}

/* ---- reading ---- */

struct cursor {
    const unsigned char* p;
    size_t len, pos;
};

/* Copies n bytes to out (if non-NULL); false if fewer than n remain. */
static bool get(struct cursor* c, void* out, size_t n)
{
    if (n > c->len - c->pos)
        return false;
    if (out)
        memcpy(out, c->p + c->pos, n);
    c->pos += n;
    return true;
}

static uint64_t get_u64(struct cursor* c)
{
    uint64_t x = 0;
    get(c, &x, 8);
    return x;
}

static double get_f64(struct cursor* c)
{
    double x = 0;
    get(c, &x, 8);
    return x;
}

static struct wetdem_vec3 get_vec(struct cursor* c)
{
    double x = get_f64(c), y = get_f64(c), z = get_f64(c);
    return (struct wetdem_vec3){x, y, z};
}

static int32_t get_i32(struct cursor* c)
{
    int32_t x = 0;
    get(c, &x, 4);
    return x;
}

static unsigned char get_u8(struct cursor* c)
{
    unsigned char x = 0;
    get(c, &x, 1);
    return x;
}

static void parse_meta(struct cursor* c, struct wetdem_checkpoint* ck)
{
    ck->time = get_f64(c);
    ck->step = get_u64(c);
    ck->config_hash = get_u64(c);
    ck->n_particles = get_u64(c);
    ck->n_walls = get_u64(c);
    ck->n_pairs = get_u64(c);
    ck->history_len = get_u64(c);
    ck->n_energy = get_u64(c);
    struct wetdem_stats* s = &ck->stats;
    unsigned long long* stats[6] = {&s->steps,      &s->rejected_steps, &s->force_evals,
                                    &s->pair_evals, &s->root_evals,     &s->events};
    for (int k = 0; k < 6; k++)
        *stats[k] = get_u64(c);
    struct wetdem_checkpoint_output* o = &ck->output;
    o->vtk_files = get_u64(c);
    o->csv_rows = get_u64(c);
    o->next_vtk_step = get_u64(c);
    o->next_csv_step = get_u64(c);
}

/* Checks that the payload holds exactly count records of record_bytes, then allocates count
 * elements of elem_size bytes (at least 1 byte) into *out, which must still be empty (a
 * repeated section is malformed). */
static int alloc_checked(void** out, uint64_t count, size_t record_bytes, size_t elem_size,
                         uint64_t payload)
{
    if (*out || count > payload / (record_bytes ? record_bytes : 1) ||
        count * record_bytes != payload)
        return WETDEM_ERR_PARSE;
    *out = malloc(count ? (size_t)count * elem_size : 1);
    return *out ? WETDEM_OK : WETDEM_ERR_NOMEM;
}

static int parse_part(struct cursor* c, struct wetdem_checkpoint* ck, uint64_t bytes)
{
    int st = alloc_checked((void**)&ck->particles, ck->n_particles, PART_BYTES,
                           sizeof *ck->particles, bytes);
    if (st != WETDEM_OK)
        return st;
    for (size_t k = 0; k < ck->n_particles; k++) {
        struct wetdem_particle* p = &ck->particles[k];
        memset(p, 0, sizeof *p);
        p->pos = get_vec(c);
        p->vel = get_vec(c);
        p->omega = get_vec(c);
        p->radius = get_f64(c);
        p->mass = get_f64(c);
        p->material = get_i32(c);
        p->is_fixed = get_u8(c) != 0;
        get(c, NULL, 3);
    }
    return WETDEM_OK;
}

static int parse_wall(struct cursor* c, struct wetdem_checkpoint* ck, uint64_t bytes)
{
    int st = alloc_checked((void**)&ck->walls, ck->n_walls, WALL_BYTES, sizeof *ck->walls, bytes);
    for (size_t k = 0; st == WETDEM_OK && k < ck->n_walls; k++) {
        ck->walls[k].point = get_vec(c);
        ck->walls[k].normal = get_vec(c);
        ck->walls[k].material = get_i32(c);
        get(c, NULL, 4);
    }
    return st;
}

static int parse_pair(struct cursor* c, struct wetdem_checkpoint* ck, uint64_t bytes)
{
    uint64_t hist = ck->n_pairs * ck->history_len;
    if (ck->history_len && hist / ck->history_len != ck->n_pairs)
        return WETDEM_ERR_PARSE;
    if (ck->n_pairs > bytes / KEY_BYTES || bytes - ck->n_pairs * KEY_BYTES != 8 * hist)
        return WETDEM_ERR_PARSE;
    int st = alloc_checked((void**)&ck->pairs, ck->n_pairs, KEY_BYTES, sizeof *ck->pairs,
                           ck->n_pairs * KEY_BYTES);
    if (st == WETDEM_OK)
        st = alloc_checked((void**)&ck->history, hist, 8, sizeof(double), 8 * hist);
    for (size_t k = 0; st == WETDEM_OK && k < ck->n_pairs; k++) {
        ck->pairs[k].i = get_u64(c);
        ck->pairs[k].j = get_u64(c);
        ck->pairs[k].is_wall = get_u8(c) != 0;
        get(c, NULL, 7);
    }
    if (st == WETDEM_OK && hist)
        get(c, ck->history, 8 * hist);
    return st;
}

static int parse_blob(struct cursor* c, unsigned char** out, size_t* size, uint64_t bytes)
{
    int st = alloc_checked((void**)out, bytes, 1, 1, bytes);
    if (st == WETDEM_OK) {
        *size = (size_t)bytes;
        get(c, *out, (size_t)bytes);
    }
    return st;
}

static int parse_section(struct cursor* c, const char tag[4], uint64_t bytes,
                         struct wetdem_checkpoint* ck)
{
    if (!memcmp(tag, "PART", 4))
        return parse_part(c, ck, bytes);
    if (!memcmp(tag, "WALL", 4))
        return parse_wall(c, ck, bytes);
    if (!memcmp(tag, "PAIR", 4))
        return parse_pair(c, ck, bytes);
    if (!memcmp(tag, "ENER", 4)) {
        int st = alloc_checked((void**)&ck->energy, ck->n_energy, 8, sizeof(double), bytes);
        if (st == WETDEM_OK)
            get(c, ck->energy, (size_t)bytes);
        return st;
    }
    if (!memcmp(tag, "RNG_", 4)) {
        if (bytes < WETDEM_CHECKPOINT_RNG_NAME)
            return WETDEM_ERR_PARSE;
        get(c, ck->rng_name, WETDEM_CHECKPOINT_RNG_NAME);
        ck->rng_name[WETDEM_CHECKPOINT_RNG_NAME - 1] = 0;
        return parse_blob(c, &ck->rng_state, &ck->rng_size, bytes - WETDEM_CHECKPOINT_RNG_NAME);
    }
    if (!memcmp(tag, "USER", 4))
        return parse_blob(c, &ck->extra, &ck->extra_size, bytes);
    if (!memcmp(tag, "NOTE", 4)) { /* text without its NUL, which none of its bytes is */
        int st = alloc_checked((void**)&ck->note, bytes + 1, 1, 1, bytes + 1);
        if (st == WETDEM_OK) {
            get(c, ck->note, (size_t)bytes);
            ck->note[bytes] = '\0';
            if (memchr(ck->note, '\0', (size_t)bytes))
                st = WETDEM_ERR_PARSE;
        }
        return st;
    }
    get(c, NULL, (size_t)bytes); /* unknown section of a later minor revision: skip */
    return WETDEM_OK;
}

/* Validates header and CRC of the whole image. */
static int check_image(const unsigned char* d, size_t len, const char* path, char* msg, size_t n)
{
    if (len < HEADER_BYTES + 4 || memcmp(d, MAGIC, 8) != 0)
        return wetdem_status_fail(msg, n, WETDEM_ERR_PARSE, "'%s' is not a wetdem checkpoint",
                                  path);
    uint32_t version, mark, crc;
    memcpy(&version, d + 8, 4);
    memcpy(&mark, d + 12, 4);
    if (mark != ENDIAN_MARK)
        return wetdem_status_fail(
            msg, n, WETDEM_ERR_PARSE,
            "checkpoint '%s' was written on a machine of the other byte order", path);
    if (version != WETDEM_CHECKPOINT_VERSION)
        return wetdem_status_fail(
            msg, n, WETDEM_ERR_PARSE,
            "checkpoint '%s' has format version %u; this wetdem reads version %u", path, version,
            WETDEM_CHECKPOINT_VERSION);
    memcpy(&crc, d + len - 4, 4);
    if (crc != wetdem_checkpoint_crc32(0, d, len - 4))
        return wetdem_status_fail(msg, n, WETDEM_ERR_PARSE,
                                  "checkpoint '%s' is corrupted or truncated (CRC mismatch)", path);
    return WETDEM_OK;
}

static int parse_image(const unsigned char* d, size_t len, struct wetdem_checkpoint* ck)
{
    struct cursor c = {d, len - 4, HEADER_BYTES};
    bool have_meta = false;
    while (c.pos < c.len) {
        char tag[4];
        uint64_t bytes = 0;
        if (!get(&c, tag, 4) || !get(&c, NULL, 4) || !get(&c, &bytes, 8) || bytes > c.len - c.pos)
            return WETDEM_ERR_PARSE;
        size_t end = c.pos + (size_t)bytes;
        int st = WETDEM_OK;
        if (!memcmp(tag, "META", 4)) {
            if (have_meta || bytes < META_BYTES)
                return WETDEM_ERR_PARSE;
            parse_meta(&c, ck);
            have_meta = true;
        } else if (!have_meta) {
            return WETDEM_ERR_PARSE;
        } else {
            st = parse_section(&c, tag, bytes, ck);
        }
        if (st != WETDEM_OK)
            return st;
        c.pos = end; /* also skips META fields added by later minor revisions */
    }
    bool complete = have_meta && (ck->particles || !ck->n_particles) &&
                    (ck->walls || !ck->n_walls) && (ck->pairs || !ck->n_pairs) &&
                    (ck->energy || !ck->n_energy);
    return complete ? WETDEM_OK : WETDEM_ERR_PARSE;
}

static int slurp(const char* path, unsigned char** data, size_t* len, char* msg, size_t n)
{
    FILE* f = fopen(path, "rb");
    if (!f)
        return wetdem_status_fail(msg, n, WETDEM_ERR_IO, "cannot open checkpoint '%s': %s", path,
                                  strerror(errno));
    /* (a directory opens for reading; its size is no file's, which read as out of memory) */
    struct stat st;
    int err = fstat(fileno(f), &st) != 0 ? errno : (S_ISDIR(st.st_mode) ? EISDIR : 0);
    if (err) {
        fclose(f);
        return wetdem_status_fail(msg, n, WETDEM_ERR_IO, "cannot read checkpoint '%s': %s", path,
                                  strerror(err));
    }
    long size = (fseek(f, 0, SEEK_END) == 0) ? ftell(f) : -1;
    err = size < 0 ? errno : 0;
    *data = size >= 0 ? malloc(size ? (size_t)size : 1) : NULL;
    bool ok = *data && fseek(f, 0, SEEK_SET) == 0 &&
              (fread(*data, 1, (size_t)size, f) == (size_t)size || ((err = errno), false));
    fclose(f);
    if (!ok) {
        bool no_memory = size >= 0 && !*data;
        free(*data);
        *data = NULL;
        if (no_memory)
            return wetdem_status_fail(msg, n, WETDEM_ERR_NOMEM,
                                      "cannot read checkpoint '%s': out of memory for its %ld "
                                      "bytes",
                                      path, size);
        return wetdem_status_fail(msg, n, WETDEM_ERR_IO, "cannot read checkpoint '%s': %s", path,
                                  err ? strerror(err) : "read failed");
    }
    *len = (size_t)size;
    return WETDEM_OK;
}

int wetdem_checkpoint_read(const char* path, struct wetdem_checkpoint* ck, char* msg,
                           size_t msg_size)
{
    memset(ck, 0, sizeof *ck);
    unsigned char* data = NULL;
    size_t len = 0;
    int st = slurp(path, &data, &len, msg, msg_size);
    if (st == WETDEM_OK)
        st = check_image(data, len, path, msg, msg_size);
    if (st == WETDEM_OK) {
        st = parse_image(data, len, ck);
        if (st != WETDEM_OK) {
            wetdem_checkpoint_clear(ck);
            wetdem_status_fail(msg, msg_size, st,
                               st == WETDEM_ERR_NOMEM
                                   ? "out of memory reading checkpoint '%s'"
                                   : "checkpoint '%s' is malformed (sections or sizes "
                                     "inconsistent)",
                               path);
        }
    }
    free(data);
    return st;
}

void wetdem_checkpoint_clear(struct wetdem_checkpoint* ck)
{
    free(ck->particles);
    free(ck->walls);
    free(ck->pairs);
    free(ck->history);
    free(ck->rng_state);
    free(ck->energy);
    free(ck->extra);
    free(ck->note);
    memset(ck, 0, sizeof *ck);
}

int wetdem_checkpoint_save_rng(struct wetdem_checkpoint* ck, const gsl_rng* rng)
{
    size_t size = gsl_rng_size(rng);
    unsigned char* s = malloc(size ? size : 1);
    if (!s)
        return WETDEM_ERR_NOMEM;
    memcpy(s, gsl_rng_state(rng), size);
    free(ck->rng_state);
    ck->rng_state = s;
    ck->rng_size = size;
    memset(ck->rng_name, 0, sizeof ck->rng_name);
    const char* name = gsl_rng_name(rng);
    memcpy(ck->rng_name, name, strnlen(name, sizeof ck->rng_name - 1));
    return WETDEM_OK;
}

int wetdem_checkpoint_restore_rng(const struct wetdem_checkpoint* ck, gsl_rng* rng, char* msg,
                                  size_t msg_size)
{
    if (strcmp(ck->rng_name, gsl_rng_name(rng)) != 0 || ck->rng_size != gsl_rng_size(rng))
        return wetdem_status_fail(
            msg, msg_size, WETDEM_ERR_INVALID,
            "checkpoint RNG is '%s' (%zu bytes), the run uses '%s' (%zu bytes)", ck->rng_name,
            ck->rng_size, gsl_rng_name(rng), gsl_rng_size(rng));
    memcpy(gsl_rng_state(rng), ck->rng_state, ck->rng_size);
    return WETDEM_OK;
}
