#include "progress.h"

static _Thread_local veil_progress_fn t_fn;
static _Thread_local void* t_user;

veil_progress_fn veil_progress_sink(veil_progress_fn fn, void* user, void** old_user)
{
    veil_progress_fn old = t_fn;
    if (old_user) *old_user = t_user;
    t_fn = fn;
    t_user = user;
    return old;
}

int veil_progress_wanted(void) { return t_fn != 0; }

void veil_progress(const char* what, double done, double total)
{
    if (t_fn) t_fn(t_user, what, done, total);
}
