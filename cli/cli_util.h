/*
 * cli_util.h — small helpers shared by the CLI subcommands: error messages, strict number
 * parsing, "A:B:N" value ranges, "--set KEY=VALUE" parameters, the provenance header of CSV
 * output, writing a table whole or not at all, and the text of a parameter's default. Uses only the public header wetdem.h.
 *
 * Conventions: every function that can reject user input prints one line
 * "wetdem: <what>: <why>" to stderr and returns an exit code (CLI_EXIT_USAGE, i.e. 2, for bad
 * input; CLI_EXIT_OK, i.e. 0, on success), so callers can write
 *     if ((rc = cli_parse_range(...)) != CLI_EXIT_OK) return rc;
 */
#ifndef WETDEM_CLI_UTIL_H
#define WETDEM_CLI_UTIL_H

#include <stdbool.h>
#include <stddef.h>
#include <stdio.h>

#include "cli.h"

/* A sequence of n values from first to last, evenly spaced (or geometrically when is_log). */
/* Most points of a sweep (--values N) or a map (N x N2): 1e7 points of some 0.8 kB. */
#define CLI_MAX_BATCH_POINTS 1e7

struct cli_range {
    double first, last; /* end points, both included */
    size_t n;           /* number of values, >= 1 */
    bool is_log;        /* geometric spacing: first and last must be > 0 */
};

/* Prints "wetdem: " followed by the printf-style message and a newline to stderr. */
void cli_error(const char* fmt, ...) __attribute__((format(printf, 1, 2)));

/* Parses the whole of `text` as one finite number in plain decimal or exponent notation
 * ("6.35e-3", "-2", "+.5E4": the syntax docs/scenarios.md gives; not hexadecimal, "inf" or
 * "nan", which strtod would also take, nor a value beyond the range of a double or below
 * its smallest normal value). 0 and *out set; or -1 (syntax), -2 (overflow), -3 (underflow). */
int cli_number(const char* text, double* out);

/* What is wrong with `text` as a number ("not a finite number", "beyond the range of a double
 * ...", "below the smallest normal double ..."); NULL when cli_number takes it. */
const char* cli_number_problem(const char* text);

/* The likely slip behind a `text` that cli_number refuses, as ": <what to write>" (for
 * "%s" after the error) into buf, or "" when none is recognised: a unit after the number
 * ("2 mm": the value in `unit`, 0.002, converted for an SI prefix of it; `unit` NULL or "-"
 * when the value has none), a decimal comma ("0,5"), a percentage of a dimensionless value,
 * an inline comment without its blank ("0.1;x"), quotes. Returns buf. */
const char* cli_number_hint(const char* text, const char* unit, char* buf, size_t n);

/* Parses `text` as one finite number (cli_number). `what`
 * names the option in the error message, e.g. "--speed". Returns CLI_EXIT_OK and sets *out,
 * or prints an error and returns CLI_EXIT_USAGE. */
int cli_parse_double(const char* text, const char* what, double* out);

/* Parses "A:B:N" (N an integer >= 1; N = 1 requires A == B) into *r with r->is_log = is_log.
 * With is_log, A and B must be > 0. `what` names the option in the error message.
 * Returns CLI_EXIT_OK, or prints an error and returns CLI_EXIT_USAGE. */
int cli_parse_range(const char* text, bool is_log, const char* what, struct cli_range* r);

/* The k-th value (0 <= k < r->n) of a parsed range; the end points are returned exactly. */
double cli_range_value(const struct cli_range* r, size_t k);

/* The exit code of a library call that set up a run from the user's input and failed with
 * `status`: CLI_EXIT_RUNTIME when it ran out of memory (WETDEM_ERR_NOMEM), which is no fault
 * of the input, CLI_EXIT_USAGE for every other failure. */
int cli_setup_exit(int status);

/* The exit code of a run that the library stopped with `status` < 0: CLI_EXIT_USAGE when it
 * refused the input before the first step (WETDEM_ERR_INVALID: a parameter or state the run
 * cannot start from, e.g. nijssen's h_min reaching its cut-off), CLI_EXIT_RUNTIME otherwise. */
int cli_run_exit(int status);

/* Applies "KEY=VALUE" to sim through wetdem_sim_set_param_str (so enumerated parameters may
 * be given by word). Returns CLI_EXIT_OK, or prints "wetdem: --set KEY=VALUE: <library
 * message>" and returns CLI_EXIT_USAGE. */
int cli_apply_set(struct wetdem_sim* sim, const char* key_value);

/* Whether any argument after the subcommand name is "--help" or "-h": every subcommand then
 * prints its usage to stdout and exits 0, whatever else is on the line. */
bool cli_wants_help(int argc, char** argv);

/* When arg is one of the options of what ({OPTION, WHAT it takes or NULL, ..., NULL}), which
 * take a value: prints "CMD: OPTION needs a value (WHAT)" and returns true (a parser that
 * found no value after it); else false. */
bool cli_needs_value(const char* cmd, const char* arg, const char* const* what);
/* Whether arg is one of `names` (NULL-terminated). */
bool cli_name_in(const char* arg, const char* const* names);
/* " (did you mean 'NAME'?)" for the name among `options` (NULL-terminated) closest to a
 * misspelt option `arg` (wetdem_param_suggest), written into buf; "" when arg is one of them
 * (cli_needs_value reports a known option whose value is missing), does not start with '-' or
 * nothing is close. Returns buf, for "%s". */
const char* cli_option_hint(const char* arg, const char* const* options, char* buf, size_t n);

/* Refuses an option given a second time that takes one value: `once` lists such options of
 * the command (NULL-terminated, at most 32), *seen has a bit for each given so far (0 at
 * first). Call it with every argument at an option's place (not with the options' values);
 * others pass. Returns CLI_EXIT_OK, or prints "wetdem: <cmd>: <arg> is given twice: give it
 * once ..." and returns CLI_EXIT_USAGE: the later value would replace the earlier unseen
 * (`sweep --param A --param B` swept B). */
int cli_option_once(const char* cmd, const char* arg, const char* const* once, unsigned* seen);

/* Splits a CSV line in place at commas into at most max fields f[], blanks trimmed. Returns
 * the number of fields. */
int cli_csv_split(char* line, char** f, int max);

/* Maps the header fields f[0 .. n) to the columns `names` (NULL-terminated; their SI units in
 * `units`, "-" for none): col[c] is the field of column c, or -1. A field may carry its unit,
 * "x [m]", which must be the column's ("-", "1" or "[]" for a dimensionless one): values are
 * read as they stand. Each known column at most once, no other. The fields are cut to their
 * names in place. Returns 0, or with *bad the offending field and why in err:
 * CLI_CSV_UNKNOWN, "unknown column 'X'" with a "did you mean" hint (also for a name whose
 * unit was left out: angle for angle_deg), or a unit other than the column's; or
 * CLI_CSV_TWICE, "column X appears twice (columns I and J)". The caller adds the file and
 * line. */
enum { CLI_CSV_UNKNOWN = -1, CLI_CSV_TWICE = -2 };
int cli_csv_columns(char** f, int n, const char* const* names, const char* const* units, int* col,
                    int* bad, char* err, size_t err_len);

/* Whether `name` is named as a many-particle run names the frames of a series of prefix
 * `prefix`: PREFIX_, six or more digits, .vtk. */
bool cli_is_frame_name(const char* prefix, const char* name);

/* Writes the '#' provenance lines that start every CSV wetdem writes:
 *     # wetdem <version> (git <hash>)
 *     # command: wetdem <argv[0]> <argv[1]> ...
 * argv is the subcommand's argument vector (argv[0] = subcommand name). Any lines that
 * describe the file follow them, then the header of "name [unit]" columns. */
void cli_print_provenance(FILE* f, int argc, char** argv);
/* The same two lines without their '#' ("wetdem VERSION (git HASH)\ncommand: wetdem ARGS",
 * no final newline) in a new string for the caller to free, or NULL when out of memory: the
 * provenance of a file the library writes (the many-particle CSV's csv_comment, which the
 * library writes as '#' lines). */
char* cli_provenance_text(int argc, char** argv);

/* mkdir -p: creates dir and its parents. 0, or -1 with errno set. */
int cli_make_dirs(const char* dir);
/* Checks, when the arguments are read, that an output path given as `option` of command
 * `what` can be what it names, a file (is_dir false) or a directory made if missing: a
 * name, not that of a directory (of a file) that exists, and no file on the way. NULL
 * (stdout, no output) passes. Returns CLI_EXIT_OK or CLI_EXIT_USAGE after printing why. */
int cli_check_output_path(const char* what, const char* option, const char* path, bool is_dir);

/* Checks that output `out` of `option` (NULL passes) names none of the files in[0 .. n), each
 * named in_names[k] in the message ("FILE", "--data"): the same file (device and inode) when
 * both exist, the same path otherwise. Writing over an input would destroy it. Returns
 * CLI_EXIT_OK or CLI_EXIT_USAGE after printing why. */
int cli_check_not_input(const char* what, const char* option, const char* out,
                        const char* const* in, const char* const* in_names, int n);

/* Checks that a file can be written at path (NULL passes) before the work that produces it
 * runs: makes its directory when missing and creates, then removes, the temporary file
 * cli_write_output would write. Returns CLI_EXIT_OK, or prints "wetdem: <what>: <option>
 * <path> cannot be written: <why>" and returns CLI_EXIT_USAGE. */
int cli_check_writable(const char* what, const char* option, const char* path);
/* The same for the files names[0..n) (an empty name or NULL: not written) of --out dir (NULL
 * passes), before the run that writes them: makes dir when missing and checks that each can
 * be written there. Returns CLI_EXIT_OK, or prints "wetdem: <what>: --out <dir>: ..." and
 * returns CLI_EXIT_USAGE. */
int cli_check_out_dir(const char* what, const char* dir, const char* const* names, size_t n);

/* Writes a table with write(f, ctx): to stdout when path is NULL, otherwise to path (its
 * directory is created when missing) under a temporary name renamed only when everything was
 * written, so a failed write leaves no half-written file and no temporary one. `what` names
 * the command in the message. Returns CLI_EXIT_OK, or prints "wetdem: <what>: cannot write
 * <file>: <why>" and returns CLI_EXIT_RUNTIME. */
int cli_write_output(const char* path, const char* what, void (*write)(FILE* f, const void* ctx),
                     const void* ctx);

/* One of the files of a result written as a set (cli_write_outputs); path NULL: not wanted. */
struct cli_output {
    const char* path;
    void (*write)(FILE* f, const void* ctx);
    const void* ctx;
};
#define CLI_MAX_OUTPUTS 4

/* Writes the n (at most CLI_MAX_OUTPUTS) files of one result as a set, as cli_write_output
 * writes one: all renamed to their names when every one is whole, none otherwise (an earlier
 * file of that name stays as it was). Returns an exit code. */
int cli_write_outputs(const struct cli_output* outs, size_t n, const char* what);

/* A file written while a run goes on (a trajectory streamed row by row) or after it, in an
 * --out directory: under the temporary name DIR/.NAME.tmpPID, renamed to DIR/NAME by
 * cli_out_close only when the run and every write succeeded, so an interrupted or failed run
 * leaves nothing half-written under the final name. */
/* snprintf into buf of what fits: false when it was cut (the name is then not to be used). */
bool cli_format_path(char* buf, size_t size, const char* fmt, ...)
    __attribute__((format(printf, 3, 4)));

/* The parent directory of path into dir (empty when it has none; "/" for "/x"). */
void cli_parent_dir(const char* path, char* dir, size_t n);

struct cli_out_file {
    char final[1400], tmp[1400];
    FILE* f;     /* NULL: not open (no directory, or the name is empty: the file is not wanted) */
    bool direct; /* the name is a device or FIFO (/dev/stdout, /dev/null): written in place */
    FILE* std;   /* stdout or stderr when the name is that stream's file (/dev/stdout, also
                    when it is a regular file): written through the stream, flushed, not closed */
};

/* Opens the temporary file of DIR/NAME (nothing when dir is NULL or name empty: o->f NULL).
 * A symbolic link is followed (its target is replaced, the link kept); a name that is a device
 * or FIFO is written in place. 0, or -1 after printing "wetdem: <what>: cannot write
 * DIR/NAME: <why>". */
int cli_out_open(struct cli_out_file* o, const char* what, const char* dir, const char* name);

/* Closes o; with keep, renames it to its final name when everything was written, otherwise
 * (or without keep) removes the temporary file. 0, or -1 after printing "wetdem: <what>:
 * cannot write <final>: <why>" when keep was asked for but the file could not be kept. */
int cli_out_close(struct cli_out_file* o, const char* what, bool keep);

/* Closes the n files of one result as a set: with keep, and only when every one was written
 * whole, renames them all to their final names (n <= CLI_MAX_OUTPUTS; a rename that fails
 * undoes the others, the older files put back); otherwise removes every temporary file, so a
 * run never leaves some of its files beside older ones. A set is recorded in a journal
 * (DIR/.wetdem-set.PID) while it is renamed, so that what a killed process leaves is completed
 * or taken back by the next that writes one of its files (docs/scenarios.md, Output). Files not open are skipped. 0, or -1
 * after printing "wetdem: <what>: cannot write <final>: <why>" for the first that failed. */
int cli_out_close_all(struct cli_out_file* const* files, size_t n, const char* what, bool keep);

/* v, or 0 for -0: every number wetdem prints passes through it (cli_print_double does), so
 * that a zero reads "0", never "-0". A -0 is the product or negation of a zero (the y velocity
 * -U sin(0) of a head-on impact, a smoothed spin of a dot that did not turn) and has no sign
 * a reader could use; every other value, NaN and the infinities included, is returned bit for
 * bit. */
double cli_plain_zero(double v);

/* Writes v to f with the fewest significant digits (15, 16 or 17) that read back as exactly
 * v, so CSV output is both exact and readable ("1e-05", not "1.0000000000000001e-05"). */
void cli_print_double(FILE* f, double v);

/* "an" before a word that starts with a vowel letter ("an impulse model"), else "a"
 * ("a fluid model", "a min-separation model"). */
const char* cli_article(const char* word);

/* Writes the default of a parameter as text: the chosen word for an enumeration, otherwise
 * the number in %g format. */
void cli_param_default_text(const struct wetdem_param_desc* d, char* buf, size_t n);

/* Progress of a long run (`run` of every engine) on stderr, only while stderr is a terminal:
 * one line "wetdem: WHAT (P %), E s elapsed, about L s left", redrawn in place at most every
 * CLI_PROGRESS_EVERY seconds of wall time and first after as long, so that a short run shows
 * none; the line of a run done (fraction 1) is drawn, then cleared. L extrapolates the pace
 * since the start: elapsed x fraction left / fraction done since the start. */
#define CLI_PROGRESS_EVERY 0.5
struct cli_progress {
    bool tty;     /* stderr is a terminal (nothing is shown otherwise) */
    int shown;    /* characters of the line on the terminal; 0: none */
    double start; /* omp_get_wtime() at the start [s] */
    double last;  /* wall time of the latest line, from the start [s] */
    double done0; /* fraction done at the start */
};

/* Starts the clock of p with the fraction `done` already done (a run continued from a
 * checkpoint), and looks whether stderr is a terminal. */
void cli_progress_start(struct cli_progress* p, double done);

/* Shows the line with WHAT from the printf-style fmt when it is due, `done` the fraction of
 * the run done (in [0, 1]; 1 is the last line, then cleared). */
void cli_progress_show(struct cli_progress* p, double done, const char* fmt, ...)
    __attribute__((format(printf, 3, 4)));

/* Clears the line, if one is shown: at the end of a run that stopped before it was done. */
void cli_progress_clear(struct cli_progress* p);

/* wetdem_time_progress_fn of a binary collision or a pairwise run (ctx: its struct
 * cli_progress): the line "t = T of T_END s", the fraction done t / t_end. Returns 0. */
int cli_progress_time(double t, double t_end, double elapsed, void* ctx);

#endif
