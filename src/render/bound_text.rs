//! The continuous relaxation's bound on ln OI_D as text: ln
//! bound and primal, the certificate gap, the support, the solvers' work.

use crate::bound::{Bound, RelaxationSolver};

/// The bound, its certificate gap, support and the solvers' work
/// (iterations, rounds, seconds), as `bound` prints it.
#[must_use]
pub fn bound_text(b: &Bound) -> String {
    let mut s = format!(
        "relaxation bound, N = {} of {} poses, p = {}: {:?}\n\
         ln bound   {:.9}  (log10 OI_D <= {:.6})\n\
         ln primal  {:.9}\n\
         gap        {:.3e}\n\
         support    {} poses with weight\n",
        b.n,
        b.pool_size,
        b.p,
        b.status,
        b.ln_bound,
        b.log10_bound(),
        b.ln_primal,
        b.certificate_gap,
        b.support_size,
    );
    match b.conic.status {
        Some(st) => {
            s += &format!(
                "{:<10} {st:?}, {} iterations, {} round(s), {} candidates, {:.2} s\n",
                solver_name(b),
                b.conic.iterations,
                b.conic.rounds,
                b.conic.candidates,
                b.conic.seconds
            )
        }
        None => s += &format!("{:<10} not run\n", solver_name(b)),
    }
    s += &format!(
        "first order {} rounds, {} steps, {:.2} s\ntotal      {:.2} s\n",
        b.first_order.rounds, b.first_order.steps, b.first_order.seconds, b.seconds
    );
    s
}

/// The conic solver's name.
fn solver_name(b: &Bound) -> &'static str {
    match b.conic.solver {
        RelaxationSolver::Clarabel => "clarabel",
        RelaxationSolver::Newton => "newton",
    }
}

/// The relaxation's weight per pose of its support (`bound --weights`).
#[must_use]
pub fn support_text(support: &[crate::report::WeightedPose]) -> String {
    let mut s = "pose      weight\n".to_string();
    for w in support {
        s += &format!("{:>6}  {:.6}\n", w.pose, w.w);
    }
    s
}
