/* mbd2d-solve's number formats without Fortran internal I/O (which allocates per statement
 * in libgfortran), as C and Python write them: kind 1 "%.16e" (17 significant digits,
 * correctly rounded, lower-case e, an exponent of at least two digits: every mbd2d CSV),
 * 2 "%.17g" (the sweep CSV: Python's format(x, ".17g")), 3 "%g" (six significant digits:
 * the check report's time, Python's ".6g"), 4 "%.1e", 5 "%.10f" and 6 "%.3g" (a failed
 * sweep case's message as Python writes it). x into buf; returns the length. */
#include <stdio.h>

int mbd_format(double x, int kind, char *buf, int len)
{
    const char *fmt = kind == 1 ? "%.16e" : kind == 2 ? "%.17g" : kind == 4 ? "%.1e"
                      : kind == 5 ? "%.10f" : kind == 6 ? "%.3g" : "%g";
    return snprintf(buf, (size_t) len, fmt, x);
}
