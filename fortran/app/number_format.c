/* mbd2d-solve's number format without Fortran internal I/O (which allocates per statement
 * in libgfortran): x as C's and Python's "%.16e" (17 significant digits, correctly rounded,
 * lower-case e, an exponent of at least two digits) into buf; returns the length. */
#include <stdio.h>

int mbd_format_e16(double x, char *buf, int len)
{
    return snprintf(buf, (size_t) len, "%.16e", x);
}

/* x as C's and Python's "%.17g" (the sweep CSV: mbd2d.write_sweep writes format(x, ".17g")). */
int mbd_format_g17(double x, char *buf, int len)
{
    return snprintf(buf, (size_t) len, "%.17g", x);
}

/* x as C's and Python's "%g" (six significant digits; the check report's time). */
int mbd_format_g6(double x, char *buf, int len)
{
    return snprintf(buf, (size_t) len, "%g", x);
}
