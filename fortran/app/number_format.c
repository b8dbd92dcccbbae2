/* mbd2d-solve's number formats without Fortran internal I/O (which allocates per statement
 * in libgfortran), as C and Python write them: kind 1 "%.16e" (17 significant digits,
 * correctly rounded, lower-case e, an exponent of at least two digits: every mbd2d CSV),
 * 2 "%.17g" (the sweep CSV: Python's format(x, ".17g")), 3 "%g" (six significant digits:
 * the check report's time). x into buf; returns the length. */
#include <stdio.h>

int mbd_format(double x, int kind, char *buf, int len)
{
    const char *fmt = kind == 1 ? "%.16e" : kind == 2 ? "%.17g" : "%g";
    return snprintf(buf, (size_t) len, fmt, x);
}
