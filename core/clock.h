/* veil — a monotonic wall clock for stage reports and progress. */
#ifndef VEIL_CLOCK_H
#define VEIL_CLOCK_H

/* Monotonic wall time in milliseconds (an arbitrary origin). */
double veil_now_ms(void);

#endif
