/* SPDX-License-Identifier: Apache-2.0 */
/* SIGINT and SIGTERM: the first one asks the library to cancel (through the
 * progress callback, so it unwinds and frees as on any error) and arms a
 * one-second watchdog; if the library has not returned by then, or a second
 * signal comes, the handler removes the partial and finished outputs of this
 * run and exits at once. Either way: no output file, exit status 128 +
 * signal (130 for SIGINT, 143 for SIGTERM). */
#include "vdbpack/vdbpack.h"

#include <signal.h>
#include <sys/stat.h>
#include <string.h>
#include <unistd.h>

#include "cli/cli.h"

#define MAX_TRACKED 4
static volatile sig_atomic_t g_signal = 0;
static volatile sig_atomic_t g_done = 0;
/* the regular files (links followed) of the outputs this run has written,
 * resolved when tracked: the handler only unlinks them */
static char g_outputs[MAX_TRACKED][4096];
static volatile sig_atomic_t g_noutputs = 0;

static void put(const char *s) {
    ssize_t r = write(2, s, strlen(s));
    (void)r;
}

static void remove_tracked(void) {
    for (int i = 0; i < g_noutputs && i < MAX_TRACKED; i++) unlink(g_outputs[i]);
}

static void finish_now(void) {
    vp_remove_partial_outputs();
    remove_tracked();
    put(g_signal == SIGTERM ? "vdbpack: terminated (SIGTERM); no output written\n"
                            : "vdbpack: interrupted (SIGINT); no output written\n");
    _exit(128 + (int)g_signal);
}

static void on_alarm(int sig) {
    (void)sig;
    if (!g_done) finish_now();
}

static void on_signal(int sig) {
    if (g_done) _exit(0); /* everything is written: nothing to undo */
    if (g_signal) finish_now();
    g_signal = sig;
    alarm(1);
}

/* A crash (in practice inside a third-party library: libblosc, which
 * OpenVDB compresses with, dereferences a failed allocation under a tight
 * ulimit -v): the partial and finished outputs of this run are removed,
 * one line says what happened, and the signal is raised again with its
 * default action, so the exit status still tells a crash (139 for
 * SIGSEGV). Not under AddressSanitizer, which reports crashes itself. */
#if defined(__SANITIZE_ADDRESS__)
#define VP_NO_CRASH_HANDLER 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define VP_NO_CRASH_HANDLER 1
#endif
#endif

#ifndef VP_NO_CRASH_HANDLER
static void on_crash(int sig) {
    vp_remove_partial_outputs();
    remove_tracked();
    put(sig == SIGSEGV   ? "vdbpack: crashed (SIGSEGV)"
        : sig == SIGBUS  ? "vdbpack: crashed (SIGBUS)"
        : sig == SIGABRT ? "vdbpack: aborted (SIGABRT)"
        : sig == SIGFPE  ? "vdbpack: crashed (SIGFPE)"
                         : "vdbpack: crashed (SIGILL)");
    put("; its outputs were removed. Memory running out under a limit (ulimit -v) "
        "does this inside OpenVDB's libraries; otherwise it is a bug: please report it\n");
    signal(sig, SIG_DFL);
    raise(sig);
}

static void install_crash_handler(void) {
    /* on a stack of its own: a stack overflow is a crash too */
    static char alt[1 << 16];
    stack_t st;
    memset(&st, 0, sizeof st);
    st.ss_sp = alt;
    st.ss_size = sizeof alt;
    int onstack = sigaltstack(&st, NULL) == 0;
    struct sigaction sa;
    memset(&sa, 0, sizeof sa);
    sigemptyset(&sa.sa_mask);
    sa.sa_flags = SA_RESETHAND | (onstack ? SA_ONSTACK : 0);
    sa.sa_handler = on_crash;
    const int sigs[] = {SIGSEGV, SIGBUS, SIGFPE, SIGILL, SIGABRT};
    for (size_t i = 0; i < sizeof sigs / sizeof sigs[0]; i++) sigaction(sigs[i], &sa, NULL);
}
#endif

void vp_cli_signals_install(void) {
#ifndef VP_NO_CRASH_HANDLER
    install_crash_handler();
#endif
    struct sigaction sa;
    memset(&sa, 0, sizeof sa);
    sigemptyset(&sa.sa_mask);
    sa.sa_flags = SA_RESTART;
    sa.sa_handler = on_signal;
    sigaction(SIGINT, &sa, NULL);
    sigaction(SIGTERM, &sa, NULL);
    sa.sa_handler = on_alarm;
    sigaction(SIGALRM, &sa, NULL);
    /* past the file-size limit (ulimit -f) a write should fail with EFBIG,
     * which the writers report and clean up, not kill the process */
    signal(SIGXFSZ, SIG_IGN);
    /* a pipe whose reader has gone (-o /dev/stdout | head): the write
     * fails with EPIPE, which is reported, and the temporary file removed */
    signal(SIGPIPE, SIG_IGN);
}

int vp_cli_interrupted(void) { return (int)g_signal; }

void vp_cli_signals_track_output(const char *path) {
    /* only a regular file this run wrote is removed, the file a symbolic
     * link names rather than the link: never a device or FIFO written
     * through (-o /dev/null) */
    if (g_noutputs >= MAX_TRACKED) return;
    char file[sizeof g_outputs[0]];
    if (!vp_output_file(path, file, sizeof file)) return;
    for (int i = 0; i < g_noutputs; i++)
        if (!strcmp(g_outputs[i], file)) return;
    memcpy(g_outputs[g_noutputs], file, sizeof file);
    g_noutputs = g_noutputs + 1; /* published once its name is complete */
}

void vp_cli_signals_done(void) {
    g_done = 1;
    alarm(0);
}

int vp_cli_interrupted_exit(void) {
    alarm(0);
    remove_tracked();
    put(g_signal == SIGTERM ? "vdbpack: terminated (SIGTERM); no output written\n"
                            : "vdbpack: interrupted (SIGINT); no output written\n");
    return 128 + (int)g_signal;
}

int vp_cli_finish_output(struct vp_context *ctx, int failed, const char *out) {
    if (failed)
        return vp_cli_interrupted() ? vp_cli_interrupted_exit()
                                    : vp_cli_die(1, "%s", vp_context_message(ctx));
    if (vp_cli_interrupted()) {
        vp_cli_signals_track_output(out);
        return vp_cli_interrupted_exit();
    }
    vp_cli_signals_done();
    return 0;
}
