/*
 * fuzz_track.c — libFuzzer target: any bytes as the dots CSV of `wetdem track` (rows
 * frame,sphere,x1,y1,x2,y2,x3,y3 in pixels), read and tracked as
 * `wetdem track FILE --fps 5000 --pixel-size 0.000175 --radius 0.0127 --mass 0.0684
 * --viscosity 0.05` does (the camera of examples/tracks/punch_45deg.csv, the corpus's seed).
 * A finding is a crash, a sanitizer report, a leak, a hang, or an exit code other than 0 and
 * 2 (fuzz_cli.h).
 */
#include "fuzz_cli.h"

int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size)
{
    fuzz_cli_on_file(data, size, "csv",
                     (const char* const[]){"track", "FILE", "--fps", "5000", "--pixel-size",
                                           "0.000175", "--radius", "0.0127", "--mass", "0.0684",
                                           "--viscosity", "0.05", NULL});
    return 0;
}
