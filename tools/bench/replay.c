#include "replay.h"

#include "clock.h"
#include "instance.h"

sw_replay sw_replay_clip(sinew_instance *inst, const double *T, int nframes, int nbones, float dt) {
    return (sw_replay){.inst = inst, .T = T, .nframes = nframes, .nbones = nbones, .dt = dt};
}

void sw_replay_run(sw_replay *r) {
    const size_t pose = (size_t)12 * r->nbones;
    r->warmup_failed = r->failed = 0;
    r->result = SINEW_OK;
    for (int f = 0; f < r->warmup; ++f) {
        sw_instance_set_pose_d(r->inst, r->T + (size_t)(f % r->nframes) * pose);
        r->warmup_failed +=
            sinew_instance_step(r->inst, r->warmup_dt > 0 ? r->warmup_dt : r->dt) != SINEW_OK;
    }
    if (r->count_rt) sw_rt_count_begin();
    for (int s = 0; s < r->steps; ++s) {
        int f = s % r->nframes;
        if (r->before && (r->result = r->before(r->user, s, f)) != SINEW_OK) break;
        double t0 = sw_now_seconds();
        if (r->post_null) sinew_instance_set_pose(r->inst, NULL, 0);
        sw_instance_set_pose_d(r->inst, r->T + (size_t)f * pose);
        r->failed += sinew_instance_step(r->inst, r->dt) != SINEW_OK;
        if (r->pos) sinew_instance_read_surface(r->inst, r->pos, r->nrm, r->ns);
        double ms = 1e3 * (sw_now_seconds() - t0);
        if (!r->on_step) continue;
        sinew_step_stats st = {.struct_size = sizeof st};
        sinew_instance_get_stats(r->inst, &st);
        r->on_step(r->user, s, f, ms, &st);
    }
    if (r->count_rt) r->counts = sw_rt_count_end();
}
