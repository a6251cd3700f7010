/* veil — the progress of long work, for whoever shows it (the CLI, on a
 * terminal). The pipeline says what it is doing: a stage begins ("inject",
 * done 0 of 1), a measured part of it is done ("RBF splat", evaluations
 * done of all). A sink installed on a thread receives the calls that
 * thread makes; with none, a call costs a test of a thread-local pointer.
 * Work that runs on the GPU is made to finish before it is reported when
 * veil_progress_wanted() (a report of submitted work would say nothing). */
#ifndef VEIL_PROGRESS_H
#define VEIL_PROGRESS_H

/* what: a short phrase, valid only during the call; 0 <= done <= total. */
typedef void (*veil_progress_fn)(void* user, const char* what, double done, double total);

/* Installs fn (NULL: none) for the calling thread; returns the one it replaces. */
veil_progress_fn veil_progress_sink(veil_progress_fn fn, void* user, void** old_user);

int veil_progress_wanted(void);
void veil_progress(const char* what, double done, double total);

/* The stage the calling thread's render is in ("inject", ...: frame/stage.h's
 * names), set by the renderer before each stage; NULL outside a render. */
void veil_progress_set_stage(const char* stage);
const char* veil_progress_stage(void);

/* Cancelling (the public progress callback, include/veil.h): a sink calls
 * veil_progress_cancel(); the pipeline tests veil_progress_cancelled()
 * where it can stop cleanly (between stages, between the march's bands and
 * the lights' optical-depth textures) and returns VEIL_ERR_CANCELLED.
 * Installing a sink clears the flag. */
void veil_progress_cancel(void);
int veil_progress_cancelled(void);

/* The calling thread's progress state (sink, stage, cancel flag), saved
 * before a caller's callback runs and restored after it: a callback may
 * render with another context on this thread (issue 41), which installs
 * its own sink and stages. */
typedef struct veil_progress_state {
    veil_progress_fn fn;
    void* user;
    const char* stage;
    int cancelled;
} veil_progress_state;
veil_progress_state veil_progress_save(void);
void veil_progress_restore(const veil_progress_state* s);

#endif
