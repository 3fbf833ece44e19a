//! Every random mechanism the build wrote (see the crate's `build/`)
//! against the multiplier oracle and its energy balance.

use appell_mechanism_check::check::{Report, Rng};
use appell_mechanism_check::{CASES, DERIVE_SECONDS, GENERATED, PANICKED, REFUSED, SEED};

/// Relative agreement every derived mechanism must reach.
const TOLERANCE: f64 = 1e-9;

#[test]
fn random_mechanisms_agree_with_the_oracle() {
    println!(
        "random mechanisms: seed {SEED:#x}, {GENERATED} generated, {} derived, {} refused, {} panicked (derive {DERIVE_SECONDS:.1} s)",
        CASES.len(),
        REFUSED.len(),
        PANICKED.len()
    );
    for r in REFUSED {
        println!("refused {} ({:?}): {}", r.name, r.families, r.message);
    }
    for p in PANICKED {
        println!(
            "PANICKED {} ({:?}): {}\n{}",
            p.name, p.families, p.message, p.source
        );
    }
    let mut total = Report::default();
    let mut failures = Vec::new();
    for (k, case) in CASES.iter().enumerate() {
        let mut rng = Rng(SEED ^ (k as u64 + 1).wrapping_mul(0xbf58_476d_1ce4_e5b9));
        match (case.check)(&mut rng) {
            Ok(report) if report.worst() <= TOLERANCE && report.states > 0 => total.merge(report),
            Ok(report) => failures.push(format!(
                "{} ({:?}): {report:?}\n{}",
                case.name, case.families, case.source
            )),
            Err(e) => failures.push(format!(
                "{} ({:?}): {e}\n{}",
                case.name, case.families, case.source
            )),
        }
    }
    println!(
        "agreed: {} of {} derived ({} models and scenes, {} states, {} singular skipped, {} energy states); largest differences: rhs {:.1e}, inverse dynamics {:.1e}, reactions {:.1e}, energy {:.1e}, Jacobian {:.1e}",
        CASES.len() - failures.len(),
        CASES.len(),
        total.variants,
        total.states,
        total.singular,
        total.energy_states,
        total.rhs,
        total.inverse_dynamics,
        total.reactions,
        total.energy,
        total.jacobian
    );
    for f in &failures {
        println!("FAILED {f}");
    }
    // At least 300 per run, unless a smaller run was asked for.
    let floor = match option_env!("APPELL_MECHANISMS") {
        Some(_) => 1,
        None => 300,
    };
    assert!(
        GENERATED >= floor,
        "{GENERATED} mechanisms, fewer than {floor}"
    );
    assert_eq!(CASES.len() + REFUSED.len() + PANICKED.len(), GENERATED);
    assert!(
        PANICKED.is_empty(),
        "the derive panicked on {} mechanisms",
        PANICKED.len()
    );
    assert!(
        REFUSED.iter().all(|r| !r.message.is_empty()),
        "every refusal carries a message"
    );
    assert!(
        failures.is_empty(),
        "{} mechanisms disagree",
        failures.len()
    );
}
