//! The plan's geometry and reach: P1 the centre, P2..P5 at 10 % of the diagonal from the
//! corners in the measuring plane, every pose reached to 1e-6 mm, the cube the largest within
//! 5 %, the plan CSV read back.

use super::*;
use crate::model::presets::preset;
use crate::Robot;
use nalgebra::Vector3;

fn kr480() -> Robot {
    preset("kuka-kr480-r3330").unwrap()
}

#[test]
fn test_points_geometry() {
    let cube = Cube {
        centre: Vector3::new(1000.0, -200.0, 800.0),
        edge_mm: 400.0,
    };
    let p = cube.test_points();
    let c = cube.plane_corners();
    assert_eq!(p[0], cube.centre);
    // The plane through C1..C4 is a diagonal plane: its corners are cube corners, C1-C3 and
    // C2-C4 space diagonals.
    let corners = cube.corners();
    for k in &c {
        assert!(corners.iter().any(|x| (x - k).norm() < 1e-12));
    }
    let normal = (c[1] - c[0]).cross(&(c[3] - c[0])).normalize();
    let diag = (c[2] - c[0]).norm();
    assert!((diag - 400.0 * 3f64.sqrt()).abs() < 1e-9);
    assert!(((c[3] - c[1]).norm() - diag).abs() < 1e-9);
    for k in 0..4 {
        let pk = p[k + 1];
        assert!(((pk - c[k]).norm() - 0.1 * diag).abs() < 1e-9, "P{}", k + 2);
        assert!(
            (pk - c[0]).dot(&normal).abs() < 1e-9,
            "P{} off the plane",
            k + 2
        );
        // On the diagonal from its corner through the centre.
        assert!((pk - c[k]).cross(&(cube.centre - c[k])).norm() < 1e-9);
    }
    // P2/P4 and P3/P5 face each other across the centre.
    assert!((p[1] + p[3] - 2.0 * cube.centre).norm() < 1e-9);
    assert!((p[2] + p[4] - 2.0 * cube.centre).norm() < 1e-9);
}

fn check_reached(robot: &Robot, plan: &Plan, joints: &[Vec<f64>]) {
    for (k, q) in joints.iter().enumerate() {
        let f = robot.tool_pose(q);
        let dp = (f.translation.vector - plan.poses[k].translation.vector).norm();
        let da = crate::compensation::rotation_angle(
            &(f.rotation.matrix() * plan.poses[k].rotation.matrix().transpose()),
        );
        assert!(dp < 1e-6, "P{}: {dp} mm", k + 1);
        assert!(
            da.to_degrees() < 1e-6,
            "P{}: {} deg",
            k + 1,
            da.to_degrees()
        );
        assert!(robot.joints_outside_limits(q).is_empty(), "P{}", k + 1);
    }
}

/// The plan's cube is in the usable workspace (whole above the floor, outside the footprint),
/// its poses reached, and it is the largest at its centre within 5 % (grown in 1 % steps until a
/// pose fails, the floor or footprint included).
fn check_largest(robot: &Robot, s: &PlanSettings) -> Plan {
    let plan = make_plan(robot, None, s).unwrap();
    assert!(!plan.compensated);
    check_reached(robot, &plan, &plan.nominal_joints);
    assert_eq!(plan.joints, plan.nominal_joints);
    let footprint = s.footprint_radius(robot);
    for c in plan.cube.corners() {
        assert!(
            c.z >= s.floor_z_mm,
            "corner {c:?} below the floor, {:?}",
            plan.cube
        );
    }
    let h = 0.5 * plan.cube.edge_mm;
    let (cx, cy) = (plan.cube.centre.x, plan.cube.centre.y);
    // The square of the cube's xy extent keeps clear of the footprint's disc: its nearest
    // point to the axis, sampled densely.
    for i in 0..=100 {
        for j in 0..=100 {
            let x = cx - h + 2.0 * h * f64::from(i) / 100.0;
            let y = cy - h + 2.0 * h * f64::from(j) / 100.0;
            assert!(
                x.hypot(y) >= footprint - 1e-9,
                "({x}, {y}) in the footprint"
            );
        }
    }
    for (k, p) in plan.cube.test_points().iter().enumerate() {
        assert!((plan.poses[k].translation.vector - p).norm() < 1e-12);
        assert!(p.z >= s.floor_z_mm);
    }
    let rotation = nalgebra::Rotation3::from_matrix_unchecked(*plan.poses[0].rotation.matrix());
    let mut reach = Reach::new(
        robot,
        None,
        rotation,
        reference_configuration(robot, s.singular_margin),
        s.singular_margin,
    );
    reach.floor_z_mm = s.floor_z_mm;
    reach.footprint_radius_mm = footprint;
    let mut edge = plan.cube.edge_mm;
    loop {
        edge *= 1.01;
        let c = Cube {
            centre: plan.cube.centre,
            edge_mm: edge,
        };
        if !reach.fits(&c) {
            break;
        }
        assert!(edge < 1.05 * plan.cube.edge_mm, "a cube of {edge} mm fits");
    }
    assert!(edge <= 1.05 * plan.cube.edge_mm);
    plan
}

#[test]
fn largest_cube_kr480() {
    let robot = kr480();
    let s = PlanSettings::default();
    let plan = check_largest(&robot, &s);
    assert!(plan.cube.edge_mm > 300.0, "{:?}", plan.cube);
    // Rows: cycle by cycle, P1, P5, P4, P3, P2.
    let rows: Vec<PlanRow> = plan.rows().collect();
    assert_eq!(rows.len(), 5 * DEFAULT_CYCLES);
    let order: Vec<usize> = rows[..10].iter().map(|r| r.pose).collect();
    assert_eq!(order, [1, 5, 4, 3, 2, 1, 5, 4, 3, 2]);
    assert_eq!((rows[5].cycle, rows[149].cycle), (2, 30));
    // A raised floor (a 1.5 m pedestal in front of the robot, say) lifts the cube.
    let high = PlanSettings {
        floor_z_mm: 1500.0,
        ..PlanSettings::default()
    };
    let lifted = check_largest(&robot, &high);
    assert!(lifted.cube.edge_mm > 100.0, "{:?}", lifted.cube);
}

/// The UR5 (base plane at z = 0, the plate it is bolted to): the cube above it.
#[test]
fn largest_cube_ur5_above_its_base_plane() {
    let robot = crate::model::robot_file::parse_robot_toml(
        include_str!("../../../../examples/ur5.toml"),
        std::path::Path::new("examples/ur5.toml"),
    )
    .unwrap();
    let plan = check_largest(&robot, &PlanSettings::default());
    assert!(plan.cube.edge_mm > 100.0, "{:?}", plan.cube);
    // A given cube through the base plane, or about the base's axis: refused, saying why.
    let low = PlanSettings {
        centre_mm: Some([400.0, 0.0, 50.0]),
        edge_mm: Some(200.0),
        ..PlanSettings::default()
    };
    let e = make_plan(&robot, None, &low).unwrap_err().to_string();
    assert!(e.contains("below the floor"), "{e}");
    let axis = PlanSettings {
        centre_mm: Some([0.0, 0.0, 600.0]),
        edge_mm: Some(100.0),
        ..PlanSettings::default()
    };
    let e = make_plan(&robot, None, &axis).unwrap_err().to_string();
    assert!(e.contains("footprint"), "{e}");
    let bad = PlanSettings {
        footprint_radius_mm: Some(-1.0),
        ..PlanSettings::default()
    };
    let e = make_plan(&robot, None, &bad).unwrap_err().to_string();
    assert!(e.starts_with("footprint_radius_mm"), "{e}");
}

#[test]
fn given_cube_and_orientation() {
    let robot = kr480();
    let s = PlanSettings {
        cycles: 3,
        edge_mm: Some(300.0),
        centre_mm: Some([2200.0, 0.0, 1500.0]),
        orientation_deg: Some([0.0, 90.0, 0.0]),
        ..PlanSettings::default()
    };
    let plan = make_plan(&robot, None, &s).unwrap();
    assert_eq!(plan.cube.edge_mm, 300.0);
    assert_eq!(plan.pose_vector_deg(1)[..3], [2200.0, 0.0, 1500.0]);
    check_reached(&robot, &plan, &plan.joints);
    // Far outside the reach: a clear error naming the setting.
    let far = PlanSettings {
        centre_mm: Some([9000.0, 0.0, 1500.0]),
        ..s.clone()
    };
    let e = make_plan(&robot, None, &far).unwrap_err().to_string();
    assert!(e.contains("does not fit") && e.contains("P1"), "{e}");
    let bad = PlanSettings { cycles: 1, ..s };
    assert!(make_plan(&robot, None, &bad)
        .unwrap_err()
        .to_string()
        .starts_with("cycles"));
}

#[test]
fn compensated_plan_and_csv_round_trip() {
    let robot = kr480();
    let cal = preset("kuka-kr480-r3330-table3").unwrap();
    let s = PlanSettings {
        cycles: 4,
        ..PlanSettings::default()
    };
    let plan = make_plan(&robot, Some(&cal), &s).unwrap();
    assert!(plan.compensated);
    check_reached(&robot, &plan, &plan.nominal_joints);
    check_reached(&cal, &plan, &plan.joints);
    assert!(plan.joints != plan.nominal_joints);
    // The same cube as the plan before calibration: the same test, other joints.
    let before = make_plan(&robot, None, &s).unwrap();
    assert_eq!(before.cube, plan.cube);
    assert_eq!(before.nominal_joints, plan.nominal_joints);

    let dir = std::env::temp_dir().join(format!("robocal-iso-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("plan.csv");
    std::fs::write(&path, plan_csv(&plan, &robot)).unwrap();
    let back = read_plan(&path, &robot, Some(&cal)).unwrap();
    assert_eq!((back.cycles, back.rows.len()), (4, 20));
    for (k, f) in back.poses.iter().enumerate() {
        assert!((f.translation.vector - plan.poses[k].translation.vector).norm() < 1e-9);
    }
    // The plan's cube and orientation read back: a plan made with them commands the same
    // poses (the test after calibration planned like the one before).
    let (cube, abc) = back.cube().unwrap();
    assert!((cube.centre - plan.cube.centre).norm() < 1e-9);
    assert!((cube.edge_mm - plan.cube.edge_mm).abs() < 1e-9);
    let again = make_plan(
        &robot,
        Some(&cal),
        &PlanSettings {
            centre_mm: Some(cube.centre.into()),
            edge_mm: Some(cube.edge_mm),
            orientation_deg: Some(abc),
            ..s.clone()
        },
    )
    .unwrap();
    for (a, b) in again.poses.iter().zip(&plan.poses) {
        assert!((a.translation.vector - b.translation.vector).norm() < 1e-9);
        let turned = crate::compensation::rotation_angle(
            &(a.rotation.matrix() * b.rotation.matrix().transpose()),
        );
        assert!(turned < 1e-12, "{turned}");
    }
    // Read without the calibrated model, the compensated joints do not reach the commanded
    // poses on the nominal one: refused as a plan for another robot.
    let e = read_plan(&path, &robot, None).unwrap_err().to_string();
    assert!(e.contains("another robot"), "{e}");
    std::fs::remove_dir_all(&dir).ok();
}
