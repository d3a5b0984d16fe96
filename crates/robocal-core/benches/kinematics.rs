//! Forward kinematics and identification Jacobian per pose (issue targets on a 2-core machine,
//! release: FK under 0.5 us, full 36-column Jacobian under 3 us).

use criterion::{black_box, criterion_group, criterion_main, Criterion};
use nalgebra::Vector3;
use robocal_core::{preset, Poe};

fn kinematics(c: &mut Criterion) {
    let r = preset("kuka-kr480-r3330-table3").unwrap();
    let q = [0.3, -0.7, 0.4, 1.1, -0.6, 2.0];
    c.bench_function("fk_tool_position_6dof", |b| {
        b.iter(|| r.tool_position(black_box(&q)))
    });
    c.bench_function("fk_tool_pose_6dof", |b| {
        b.iter(|| r.tool_pose(black_box(&q)))
    });
    let poe = Poe::from_robot(&r);
    c.bench_function("fk_poe_6dof", |b| b.iter(|| poe.tool_pose(black_box(&q))));
    let mut jp = vec![Vector3::zeros(); r.param_count()];
    let mut jq = vec![Vector3::zeros(); r.dof()];
    c.bench_function("jacobian_36_params_6dof", |b| {
        b.iter(|| r.tool_position_jacobians(black_box(&q), None, Some(&mut jp)))
    });
    c.bench_function("jacobian_36_params_and_joints_6dof", |b| {
        b.iter(|| r.tool_position_jacobians(black_box(&q), Some(&mut jq), Some(&mut jp)))
    });
}

criterion_group!(benches, kinematics);
criterion_main!(benches);
