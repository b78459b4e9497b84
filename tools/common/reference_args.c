#include "reference_args.h"

#include <stdio.h>
#include <string.h>

#include "tool_flags.h"

/* in enum order, by the names the summaries print (fullsim.h) */
static int take_solver(const char *tool, const char *flag, const char *v, void *target) {
    const char *const solvers[] = {sw_linear_solver_name(SW_SOLVER_AUTO),
                                   sw_linear_solver_name(SW_SOLVER_CHOLMOD),
                                   sw_linear_solver_name(SW_SOLVER_PCG), NULL};
    int k = sw_flags_choice(tool, flag, v, solvers);
    if (k >= 0) ((sw_fullsim_params *)target)->solver = (sw_linear_solver)k;
    return k >= 0;
}

static int take_hessian(const char *tool, const char *flag, const char *v, void *target) {
    const char *const hessians[] = {sw_hessian_mode_name(SW_HESSIAN_ADAPTIVE),
                                    sw_hessian_mode_name(SW_HESSIAN_PROJECTED),
                                    sw_hessian_mode_name(SW_HESSIAN_EXACT), NULL};
    int k = sw_flags_choice(tool, flag, v, hessians);
    if (k >= 0) ((sw_fullsim_params *)target)->hessian = (sw_hessian_mode)k;
    return k >= 0;
}

size_t sw_reference_flags(sw_fullsim_params *p, sw_flag *f) {
    static const char *const off_on[] = {"off", "on", NULL};
    const sw_flag flags[SW_REFERENCE_NFLAGS] = {
        {SW_CALL("--solver", take_solver, p, "S",
                 "the reference's linear solver: auto (default) | cholmod | pcg")},
        {SW_INT("--contact-rounds", &p->contact_rounds, 1, 100, "R",
                "the round cap, 1..100 (default 60)")},
        {SW_CHOICE("--set-check", &p->contact_set_check, off_on, "C",
                   "on (default) | off: end a round's Newton once its contact set\n"
                   "would change"),
         .range = "on or off"},
        {SW_CALL("--hessian", take_hessian, p, "M",
                 "adaptive (default) | projected | exact element Hessians")},
    };
    memcpy(f, flags, sizeof flags);
    return SW_REFERENCE_NFLAGS;
}
