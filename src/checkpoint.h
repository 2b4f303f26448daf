/*
 * checkpoint.h — binary checkpoints of a many-particle run (internal). Prefix:
 * wetdem_checkpoint. Format: docs/many.md ("Checkpoint file format") and checkpoint.c.
 */
#ifndef WETDEM_CHECKPOINT_H
#define WETDEM_CHECKPOINT_H

#include <gsl/gsl_rng.h>
#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "wetdem.h"

#define WETDEM_CHECKPOINT_VERSION 1u
#define WETDEM_CHECKPOINT_RNG_NAME 32

/* Key of one pair's history: particle i with particle j, or with wall j when is_wall. */
struct wetdem_checkpoint_pair {
    uint64_t i, j;
    bool is_wall;
};

struct wetdem_checkpoint_wall {
    struct wetdem_vec3 point;  /* [m] */
    struct wetdem_vec3 normal; /* unit, into the domain */
    int material;
};

/* Where the outputs stand, so that a resumed run continues the same file sequence. */
struct wetdem_checkpoint_output {
    uint64_t vtk_files;     /* VTK files written so far */
    uint64_t csv_rows;      /* data rows of the global-quantities CSV written so far */
    uint64_t next_vtk_step; /* step of the next VTK file */
    uint64_t next_csv_step; /* step of the next CSV row */
};

/* Everything needed to resume a run bit-identically. Arrays are owned by the caller when
 * writing; after wetdem_checkpoint_read they are malloc'ed and released by
 * wetdem_checkpoint_clear. */
struct wetdem_checkpoint {
    double time;          /* [s] */
    uint64_t step;        /* steps taken */
    uint64_t config_hash; /* fingerprint of models, parameters and settings (refuse mismatch) */
    struct wetdem_particle* particles;
    size_t n_particles;
    struct wetdem_checkpoint_wall* walls;
    size_t n_walls;
    struct wetdem_checkpoint_pair* pairs; /* n_pairs keys ... */
    double* history;                      /* ... and n_pairs x history_len doubles */
    size_t n_pairs, history_len;
    char rng_name[WETDEM_CHECKPOINT_RNG_NAME]; /* gsl_rng type name, "" if no RNG */
    unsigned char* rng_state;
    size_t rng_size; /* bytes */
    struct wetdem_stats stats;
    struct wetdem_checkpoint_output output;
    double* energy; /* energy-budget accumulators [J] */
    size_t n_energy;
    unsigned char* extra; /* opaque bytes for extensions */
    size_t extra_size;
    char* note; /* the run's checkpoint_note (NOTE section, written when not empty); NULL:
                   none */
};

/* Writes ck to path atomically (path.tmp, fsync, rename): a crash leaves the old file intact.
 * Returns WETDEM_OK, WETDEM_ERR_NOMEM or WETDEM_ERR_IO (message in msg, may be NULL). */
int wetdem_checkpoint_write(const char* path, const struct wetdem_checkpoint* ck, char* msg,
                            size_t msg_size);
/* Reads a checkpoint into *ck (zeroed first; arrays allocated). Checks magic, version, byte
 * order, sizes and the CRC-32 of the whole file. Returns WETDEM_OK, WETDEM_ERR_IO (cannot
 * read), WETDEM_ERR_PARSE (not a checkpoint, other version or byte order, truncated,
 * corrupted) or WETDEM_ERR_NOMEM; on error *ck holds nothing to release. */
int wetdem_checkpoint_read(const char* path, struct wetdem_checkpoint* ck, char* msg,
                           size_t msg_size);
/* Frees the arrays of a checkpoint filled by wetdem_checkpoint_read and zeroes it. */
void wetdem_checkpoint_clear(struct wetdem_checkpoint* ck);

/* Points ck's RNG fields at a copy of rng's state (malloc'ed; released by _clear). */
int wetdem_checkpoint_save_rng(struct wetdem_checkpoint* ck, const gsl_rng* rng);
/* Restores rng from ck. WETDEM_ERR_INVALID if the generator type or size differs. */
int wetdem_checkpoint_restore_rng(const struct wetdem_checkpoint* ck, gsl_rng* rng, char* msg,
                                  size_t msg_size);

/* CRC-32 (IEEE 802.3, reflected polynomial 0xEDB88320) of n bytes, continuing from crc
 * (start with 0). */
uint32_t wetdem_checkpoint_crc32(uint32_t crc, const void* data, size_t n);
/* 64-bit FNV-1a hash of n bytes continuing from h (start with 0): for config fingerprints. */
uint64_t wetdem_checkpoint_hash(uint64_t h, const void* data, size_t n);

#endif
