#include "progress.h"

static _Thread_local veil_progress_fn t_fn;
static _Thread_local void* t_user;
static _Thread_local const char* t_stage;
static _Thread_local int t_cancelled;

veil_progress_fn veil_progress_sink(veil_progress_fn fn, void* user, void** old_user)
{
    veil_progress_fn old = t_fn;
    if (old_user) *old_user = t_user;
    t_fn = fn;
    t_user = user;
    t_cancelled = 0;
    return old;
}

int veil_progress_wanted(void) { return t_fn != 0; }

void veil_progress(const char* what, double done, double total)
{
    if (t_fn) t_fn(t_user, what, done, total);
}

void veil_progress_set_stage(const char* stage) { t_stage = stage; }
const char* veil_progress_stage(void) { return t_stage; }
void veil_progress_cancel(void) { t_cancelled = 1; }
int veil_progress_cancelled(void) { return t_cancelled; }

veil_progress_state veil_progress_save(void)
{
    return (veil_progress_state){t_fn, t_user, t_stage, t_cancelled};
}

void veil_progress_restore(const veil_progress_state* s)
{
    t_fn = s->fn, t_user = s->user, t_stage = s->stage, t_cancelled = s->cancelled;
}
