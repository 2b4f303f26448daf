/*
 * fuzz_fit_data.c — libFuzzer target: any bytes as the data CSV of `wetdem fit` (columns
 * stokes_n, e_n and optionally angle_deg, omega_rad_s), read, checked and fitted as
 * `wetdem fit examples/fit/punch_db_c.ini --data FILE --fit glass.p_gt --max-iter 2` does (the
 * shipped example of docs/calibration.md, cut to two iterations).
 *
 * A finding is a crash, a sanitizer report, a leak, a hang, or an exit code other than 0, 1
 * and 2: bad data is exit 2, and a fit that does not converge or does not determine the key
 * in two iterations is exit 1, which any data may give. Inputs of more than MAX_ROWS lines
 * that are not comments (the header and the data rows) are passed over: each data row is a
 * collision of every model evaluation, so that a few rows keep the fuzzer at several inputs a
 * second, and the reader's limits (MAX_POINTS rows) are covered by the tests.
 */
#include "fuzz_cli.h"

int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size);

enum { MAX_ROWS = 6 };

int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size)
{
    size_t rows = 0;
    for (size_t k = 0; k < size; k++)
        rows += (k == 0 || data[k - 1] == '\n') && data[k] != '#';
    if (rows > MAX_ROWS)
        return 0;
    int rc = fuzz_cli_run_on_file(data, size, "csv",
                                  (const char* const[]){"fit", "examples/fit/punch_db_c.ini",
                                                        "--data", "FILE", "--fit", "glass.p_gt",
                                                        "--max-iter", "2", NULL});
    if (rc < 0 || rc > 2)
        abort();
    return 0;
}
