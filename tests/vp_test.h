/* Tiny assertion macros for the C unit tests (libuv style: print both
 * values and the location, then fail the test). */
#ifndef VP_TEST_H
#define VP_TEST_H
#include <stdio.h>
#include <stdlib.h>
#include <math.h>

/* Failure counter for tests that keep going after a failed check. */
static int vp_test_failures __attribute__((unused)) = 0;


#define ASSERT_TRUE(c) do { if (!(c)) { \
    fprintf(stderr, "%s:%d: assertion failed: %s\n", __FILE__, __LINE__, #c); \
    exit(1); } } while (0)
#define ASSERT_EQ_INT(a, b) do { long long va_ = (long long)(a), vb_ = (long long)(b); \
    if (va_ != vb_) { fprintf(stderr, "%s:%d: %s == %s failed: %lld != %lld\n", \
    __FILE__, __LINE__, #a, #b, va_, vb_); exit(1); } } while (0)
#define ASSERT_NEAR(a, b, tol) do { double va_ = (double)(a), vb_ = (double)(b); \
    if (!(fabs(va_ - vb_) <= (tol))) { fprintf(stderr, \
    "%s:%d: |%s - %s| <= %s failed: %.17g vs %.17g (diff %.3g)\n", \
    __FILE__, __LINE__, #a, #b, #tol, va_, vb_, fabs(va_ - vb_)); exit(1); } } while (0)
#define ASSERT_LE(a, b) do { double va_ = (double)(a), vb_ = (double)(b); \
    if (!(va_ <= vb_)) { fprintf(stderr, "%s:%d: %s <= %s failed: %.17g > %.17g\n", \
    __FILE__, __LINE__, #a, #b, va_, vb_); exit(1); } } while (0)
#define ASSERT_GE(a, b) ASSERT_LE(b, a)

#define RUN_TEST(fn) do { fprintf(stderr, "-- %s\n", #fn); fn(); } while (0)
#define RUN_TEST_ARGS(call) do { fprintf(stderr, "-- %s\n", #call); call; } while (0)
#endif
