//! A tour of the symbolic engine on the paper's wheel-axle assemblage
//! (Wang & Pao 2003, Sec. IV C): from the five velocity constraints to the
//! matrix D (eq. 65), the dependent-speed solve (eq. 27) and C_rk (eq. 66),
//! the cyclic coordinates (Sec. III C), and the Rust the derive will emit.
//! It ends with the engine's scaling on n-link spatial chains.
//!
//! Run: `cargo run --release --example engine_tour`

use std::time::Instant;

use appell::symbolic::workloads::spatial_chain;
use appell::symbolic::{
    Assumptions, EmitOptions, Graph, Id, Program, SymMatrix, Symbol, SymbolicError,
};

fn main() -> Result<(), SymbolicError> {
    let start = Instant::now();
    let mut g = Graph::new();
    // Generalized coordinates in the paper's order (eq. 65).
    let names = ["x1", "y1", "psi1", "x2", "y2", "psi2", "phi"];
    let coords: Vec<_> = names
        .iter()
        .map(|n| g.coordinate(n))
        .collect::<Result<_, _>>()?;
    let a = g.parameter("a")?;
    let _l = g.parameter("l")?;
    // Velocity constraints D q̇ + d = 0 (rolling without slip, eq. 63).
    let constraints = [
        "x1_dot - a*psi1_dot*cos(phi)",
        "y1_dot - a*psi1_dot*sin(phi)",
        "x2_dot - a*psi2_dot*cos(phi)",
        "y2_dot - a*psi2_dot*sin(phi)",
        "a*psi2_dot - a*psi1_dot + l*phi_dot",
    ];
    let rates: Vec<Symbol> = coords.iter().map(|c| c.rate).collect();
    let mut d_rows = Vec::new();
    let mut d_vec = Vec::new();
    for c in constraints {
        let e = g.parse_strict(c)?;
        let form = g.linear_coefficients(e, &rates)?;
        d_rows.extend(form.coefficients);
        d_vec.push(form.remainder);
    }
    let d = SymMatrix::from_rows(5, 7, d_rows)?;
    println!("D (eq. 65), rows over (x1, y1, psi1, x2, y2, psi2, phi):");
    for r in 0..5 {
        let row: Vec<String> = (0..7).map(|c| g.display(d[(r, c)]).to_string()).collect();
        println!("  [{}]", row.join(", "));
    }

    // Partition: dependent speeds z = (x1, y1, x2, y2, psi2), privileged
    // y = (phi, psi1). Solve D' B = −D'' and D' b = −d (eqs. 27-29).
    let dependent = [0usize, 1, 3, 4, 5];
    let privileged = [6usize, 2];
    let mut dp = Vec::new();
    let mut rhs = Vec::new();
    for r in 0..5 {
        for &c in &dependent {
            dp.push(d[(r, c)]);
        }
        for &c in &privileged {
            rhs.push(g.neg(d[(r, c)])?);
        }
        rhs.push(g.neg(d_vec[r])?);
    }
    let dp = SymMatrix::from_rows(5, 5, dp)?;
    let rhs = SymMatrix::from_rows(5, 3, rhs)?;
    let solution = g.solve_linear(&dp, &rhs, &Assumptions::new().positive(a))?;
    println!(
        "\ndet D' = {}  (pivots provably non-zero for a > 0)",
        g.display(solution.determinant)
    );

    // C_rk and c_r (eqs. 30-31): identity rows for the privileged speeds.
    let zero = g.int(0)?;
    let one = g.int(1)?;
    let mut c_entries = vec![zero; 7 * 2];
    let mut c_vec = [zero; 7];
    for (i, &r) in dependent.iter().enumerate() {
        c_entries[r * 2] = solution.x[(i, 0)];
        c_entries[r * 2 + 1] = solution.x[(i, 1)];
        c_vec[r] = solution.x[(i, 2)];
    }
    c_entries[6 * 2] = one;
    c_entries[2 * 2 + 1] = one;
    let c = SymMatrix::from_rows(7, 2, c_entries)?;
    println!("\nC_rk (eq. 66), columns phi_dot and psi1_dot:");
    let paper = [
        ["0", "a*cos(phi)"],
        ["0", "a*sin(phi)"],
        ["0", "1"],
        ["-l*cos(phi)", "a*cos(phi)"],
        ["-l*sin(phi)", "a*sin(phi)"],
        ["-l/a", "1"],
        ["1", "0"],
    ];
    for (r, name) in names.iter().enumerate() {
        let ours = [c[(r, 0)], c[(r, 1)]];
        let theirs: [Id; 2] = [g.parse_strict(paper[r][0])?, g.parse_strict(paper[r][1])?];
        let mark = if ours == theirs {
            "= paper"
        } else {
            "DIFFERS from paper"
        };
        println!(
            "  {name:>5}: [{:>12}, {:>12}]   {mark}",
            g.display(ours[0]).to_string(),
            g.display(ours[1]).to_string()
        );
        assert_eq!(ours, theirs, "C_rk row {name} disagrees with eq. 66");
    }
    assert!(c_vec.iter().all(|&e| g.is_zero(e)), "scleronomic: c_r = 0");

    // Cyclic coordinates (Sec. III C): dependent coordinates absent from C.
    let roots: Vec<Id> = c.entries().to_vec();
    let absent: Vec<&str> = coords
        .iter()
        .zip(names)
        .filter(|(q, _)| !roots.iter().any(|&e| g.depends_on(e, q.q)))
        .map(|(_, n)| n)
        .collect();
    println!("\ncoordinates absent from C_rk: {}", absent.join(", "));

    // What the derive will emit for C_rk: shared subexpressions, parameter
    // work hoisted out of the per-call body.
    let program = Program::lower(&g, &roots);
    let code = program.to_rust(&g, &EmitOptions::default());
    println!(
        "\nemitted C_rk: {} per call, {} once per parameter set",
        code.ops, code.prepare_ops
    );
    for s in code.prepare.iter().chain(&code.body) {
        println!("    {s}");
    }
    println!("    C = [{}]", code.outputs.join(", "));
    println!(
        "\nwheel-axle derivation above: {:.2} ms, {} nodes",
        start.elapsed().as_secs_f64() * 1e3,
        g.len()
    );

    println!("\nscaling: tip accelerations of n-link spatial chains");
    println!(
        "{:>3} {:>7} {:>11} {:>9} {:>9}",
        "n", "nodes", "ops(tree)", "ops(cse)", "time"
    );
    for n in [2, 4, 8, 16] {
        let t = Instant::now();
        let mut g = Graph::new();
        let chain = spatial_chain(&mut g, n)?;
        let roots = chain.acceleration_roots();
        let program = Program::lower(&g, &roots);
        let code = program.to_rust(&g, &EmitOptions::default());
        let dt = t.elapsed();
        println!(
            "{:>3} {:>7} {:>11} {:>9} {:>7.2}ms",
            n,
            g.len(),
            program.tree_op_count().total(),
            (code.ops + code.prepare_ops).total(),
            dt.as_secs_f64() * 1e3
        );
    }
    Ok(())
}
