//! Scaling of the symbolic engine on the kinematics of n-link spatial chains:
//! build (rotations, tip positions), differentiate twice in time, lower and
//! emit Rust. Prints a table (graph nodes, DAG size of the outputs, operation
//! counts before and after CSE, median phase times), then lets criterion time
//! the whole pipeline for a few sizes.
//!
//! Run: `cargo bench -p appell-symbolic --bench chain`.

use std::hint::black_box;
use std::time::{Duration, Instant};

use appell_symbolic::workloads::chain_positions;
use appell_symbolic::{EmitOptions, Graph, Id, Program, RateRules};
use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion};

struct Run {
    build: Duration,
    derive: Duration,
    emit: Duration,
    nodes: usize,
    dag: usize,
    tree_ops: usize,
    cse_ops: usize,
    hoisted_ops: usize,
}

fn run(n: usize) -> Run {
    let t0 = Instant::now();
    let mut g = Graph::new();
    let (_, positions) = chain_positions(&mut g, n).expect("positions");
    let t1 = Instant::now();
    let rules = RateRules::coordinates();
    let flat: Vec<Id> = positions.iter().flatten().copied().collect();
    let vel = g.time_derivatives(&flat, &rules).expect("velocities");
    let acc = g.time_derivatives(&vel, &rules).expect("accelerations");
    let t2 = Instant::now();
    let program = Program::lower(&g, &acc);
    let code = program.to_rust(&g, &EmitOptions::default());
    let t3 = Instant::now();
    black_box(&code);
    Run {
        build: t1 - t0,
        derive: t2 - t1,
        emit: t3 - t2,
        nodes: g.len(),
        dag: g.dag_size(&acc),
        tree_ops: program.tree_op_count().total(),
        cse_ops: code.ops.total(),
        hoisted_ops: code.prepare_ops.total(),
    }
}

fn median(mut v: Vec<Duration>) -> f64 {
    v.sort();
    v[v.len() / 2].as_secs_f64() * 1e3
}

fn table() {
    println!();
    println!(
        "n-link spatial chain: tip accelerations of every link (3n outputs), median of 7 runs"
    );
    println!(
        "{:>3} {:>8} {:>8} {:>12} {:>9} {:>8} {:>9} {:>9} {:>9} {:>9}",
        "n",
        "nodes",
        "dag",
        "ops(tree)",
        "ops(cse)",
        "hoisted",
        "build",
        "d/dt x2",
        "emit",
        "total"
    );
    for n in [2, 4, 6, 8, 10, 12, 14, 16] {
        let runs: Vec<Run> = (0..7).map(|_| run(n)).collect();
        let r = &runs[0];
        let total = median(runs.iter().map(|r| r.build + r.derive + r.emit).collect());
        println!(
            "{:>3} {:>8} {:>8} {:>12} {:>9} {:>8} {:>7.2}ms {:>7.2}ms {:>7.2}ms {:>7.2}ms",
            n,
            r.nodes,
            r.dag,
            r.tree_ops,
            r.cse_ops,
            r.hoisted_ops,
            median(runs.iter().map(|r| r.build).collect()),
            median(runs.iter().map(|r| r.derive).collect()),
            median(runs.iter().map(|r| r.emit).collect()),
            total
        );
    }
    println!();
}

fn bench(c: &mut Criterion) {
    table();
    let mut group = c.benchmark_group("spatial_chain_pipeline");
    group.sample_size(10);
    for n in [2usize, 4, 8, 16] {
        group.bench_with_input(BenchmarkId::from_parameter(n), &n, |b, &n| {
            b.iter(|| run(black_box(n)).cse_ops)
        });
    }
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
