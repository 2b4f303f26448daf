/*
 * param.c — parameter descriptors: defaults, validation with a message naming the parameter,
 * its value and valid range, enumerated choices, and "did you mean" suggestions by edit
 * distance (optimal string alignment: Levenshtein with swaps of adjacent letters; threshold one
 * third of the word length, at least 2).
 */
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "locale_guard.h"
#include "wetdem.h"

size_t wetdem_param_count(const struct wetdem_param_desc* table)
{
    size_t n = 0;
    while (table && table[n].name)
        n++;
    return n;
}

const struct wetdem_param_desc* wetdem_param_find(const struct wetdem_param_desc* table,
                                                  const char* name)
{
    for (size_t k = 0; table && name && table[k].name; k++)
        if (strcmp(table[k].name, name) == 0)
            return &table[k];
    return NULL;
}

void wetdem_param_init_defaults(const struct wetdem_param_desc* table, void* params)
{
    for (size_t k = 0; table && table[k].name; k++)
        *(double*)((char*)params + table[k].offset) = table[k].default_value;
}

static size_t count_choices(const char* const* choices)
{
    size_t n = 0;
    while (choices[n])
        n++;
    return n;
}

/* snprintf into buf + used when there is room left, else only counts: the total length of
 * the text so far, as snprintf returns it */
static size_t append(char* buf, size_t n, size_t used, const char* fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    int k = vsnprintf(used < n ? buf + used : NULL, used < n ? n - used : 0, fmt, ap);
    va_end(ap);
    return used + (k > 0 ? (size_t)k : 0);
}

size_t wetdem_param_range_text(const struct wetdem_param_desc* d, char* buf, size_t n)
{
    if (!buf)
        n = 0; /* (snprintf's convention: NULL with 0 only counts; NULL with more is no room) */
    if (n)
        buf[0] = '\0';
    if (!d)
        return 0;
    if (d->choices) {
        size_t used = append(buf, n, 0, "one of:");
        for (size_t k = 0; d->choices[k]; k++)
            used = append(buf, n, used, "%s %s", k ? "," : "", d->choices[k]);
        return used;
    }
    int digits = d->integer ? 10 : 6; /* counts in full: [0, 4294967295], not 4.29497e+09 */
    /* (in the C locale: "[0.5, 1]", not "[0,5, 1]"; without one, in the thread's) */
    struct wetdem_locale_guard g;
    (void)wetdem_locale_guard_enter(&g); /* (leave undoes only an enter that succeeded) */
    size_t used =
        append(buf, n, 0, "%s%c%.*g, %.*g%c", d->integer ? "integer in " : "",
               d->min_open ? '(' : '[', digits, d->min, digits, d->max, d->max_open ? ')' : ']');
    wetdem_locale_guard_leave(&g);
    return used;
}

size_t wetdem_param_format_value(double value, int min_digits, char* buf, size_t n)
{
    /* (clamped to 1..17: above 17 the loop ran never and left buf as it was) */
    int first = min_digits < 1 ? 1 : (min_digits > 17 ? 17 : min_digits);
    /* the text of a number for files and command lines: in the C locale (without one, which
     * does not happen with glibc or musl, in the thread's; it still reads back there). Found
     * in a buffer of its own ("%.17g" of any double is at most 24 characters), so that a short
     * or NULL buf neither stops the search early nor is read back */
    char text[40];
    struct wetdem_locale_guard g;
    (void)wetdem_locale_guard_enter(&g); /* (leave undoes only an enter that succeeded) */
    for (int digits = first; digits <= 17; digits++) {
        snprintf(text, sizeof text, "%.*g", digits, value);
        if (strtod(text, NULL) == value)
            break;
    }
    wetdem_locale_guard_leave(&g);
    if (buf && n)
        snprintf(buf, n, "%s", text);
    return strlen(text);
}

int wetdem_param_validate(const struct wetdem_param_desc* d, double value, char* msg,
                          size_t msg_size)
{
    if (!d) { /* (what wetdem_param_find answers for a name it does not know) */
        if (msg && msg_size)
            snprintf(msg, msg_size,
                     "no parameter to check the value against (NULL descriptor: a name that "
                     "wetdem_param_find did not find?)");
        return WETDEM_ERR_INVALID;
    }
    bool ok = isfinite(value);
    if (ok && d->choices) {
        double idx = floor(value);
        ok = idx == value && idx >= 0 && idx < (double)count_choices(d->choices);
    } else if (ok) {
        ok = (d->min_open ? value > d->min : value >= d->min) &&
             (d->max_open ? value < d->max : value <= d->max);
    }
    bool whole = !d->integer || value == floor(value); /* 100.5 steps: a slip, not 100 */
    if (ok && whole)
        return WETDEM_OK;
    if (msg && msg_size) { /* (the range's text only now: builds check every parameter) */
        char range[160], text[32];
        wetdem_param_range_text(d, range, sizeof range);
        /* a value just past a range's end is not printed as the end (-1.000000000001, not -1,
         * for (-1, 0.5)), nor 1e6 + 0.5 as 1e+06 */
        wetdem_param_format_value(value, 6, text, sizeof text);
        snprintf(msg, msg_size, "%s = %s [%s] is %s: valid %s", d->name, text, d->unit,
                 ok ? "not a whole number" : "out of range", range);
    }
    return WETDEM_ERR_INVALID;
}

int wetdem_param_choice_index(const struct wetdem_param_desc* d, const char* word)
{
    for (int k = 0; word && d->choices && d->choices[k]; k++)
        if (strcmp(d->choices[k], word) == 0)
            return k;
    return -1;
}

/* Edit distance of two short strings (truncated to 63 characters): insertions, deletions,
 * substitutions and swaps of two adjacent letters each count 1 (the optimal string alignment
 * distance), so that "lgo2" is 1 from "log2" and 2 from "log". */
static size_t edit_distance(const char* a, const char* b)
{
    size_t la = strlen(a), lb = strlen(b);
    if (la > 63)
        la = 63;
    if (lb > 63)
        lb = 63;
    size_t rows[3][64]; /* distances for prefixes of a of length i - 2, i - 1 and i */
    for (size_t j = 0; j <= lb; j++)
        rows[1][j] = j;
    for (size_t i = 1; i <= la; i++) {
        size_t *before = rows[0], *prev = rows[1], *cur = rows[2];
        cur[0] = i;
        for (size_t j = 1; j <= lb; j++) {
            size_t best = prev[j - 1] + (a[i - 1] == b[j - 1] ? 0 : 1);
            if (prev[j] + 1 < best)
                best = prev[j] + 1;
            if (cur[j - 1] + 1 < best)
                best = cur[j - 1] + 1;
            if (i > 1 && j > 1 && a[i - 1] == b[j - 2] && a[i - 2] == b[j - 1] &&
                before[j - 2] + 1 < best)
                best = before[j - 2] + 1;
            cur[j] = best;
        }
        memcpy(rows[0], rows[1], sizeof rows[0]);
        memcpy(rows[1], rows[2], sizeof rows[1]);
    }
    return rows[1][lb];
}

const char* wetdem_param_suggest(const char* word, const char* const* candidates)
{
    const char* best = NULL;
    size_t best_d = (size_t)-1;
    if (!word)
        return NULL;
    for (size_t k = 0; candidates && candidates[k]; k++) {
        size_t d = edit_distance(word, candidates[k]);
        if (d < best_d) {
            best_d = d;
            best = candidates[k];
        }
    }
    size_t limit = strlen(word) / 3;
    if (limit < 2)
        limit = 2;
    return best_d <= limit ? best : NULL;
}
