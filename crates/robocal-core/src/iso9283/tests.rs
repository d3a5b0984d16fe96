//! The formulas of ISO 9283 against values computed by hand on small fixed data.

use super::*;
use crate::frame::{pose, Frame};
use nalgebra::{Rotation3, Translation3, Vector3};

fn at(x: f64, y: f64, z: f64) -> Frame {
    Frame::from_parts(Translation3::new(x, y, z), Rotation3::identity())
}

fn sample(cycle: usize, p: [f64; 3]) -> Sample {
    Sample {
        cycle,
        position: Vector3::from(p),
        rotation: None,
        time_s: None,
    }
}

/// P1 commanded at the origin; attained (1,0,0), (3,0,0), (2,2,0), (2,-2,0).
fn pose1() -> PoseSamples {
    PoseSamples {
        pose: 1,
        commanded: at(0.0, 0.0, 0.0),
        samples: vec![
            sample(1, [1.0, 0.0, 0.0]),
            sample(2, [3.0, 0.0, 0.0]),
            sample(3, [2.0, 2.0, 0.0]),
            sample(4, [2.0, -2.0, 0.0]),
        ],
    }
}

/// P2 commanded 10 mm along x; attained P1's points shifted by 10 + (0, 0.2, -0.2, 0.4) in x.
fn pose2() -> PoseSamples {
    let d = [0.0, 0.2, -0.2, 0.4];
    let mut p = pose1();
    p.pose = 2;
    p.commanded = at(10.0, 0.0, 0.0);
    for (s, d) in p.samples.iter_mut().zip(d) {
        s.position.x += 10.0 + d;
    }
    p
}

const ORIGIN_BELOW: Vector3<f64> = Vector3::new(0.0, 0.0, -1000.0);

#[test]
fn ap_rp_by_hand() {
    let r = evaluate_pose(&pose1(), &TrackerMpe::default(), &ORIGIN_BELOW, None).unwrap();
    // G = (2, 0, 0): AP = 2 along x.
    assert_eq!(r.barycentre_mm, [2.0, 0.0, 0.0]);
    assert_eq!(
        (r.ap_mm, r.ap_x_mm, r.ap_y_mm, r.ap_z_mm),
        (2.0, 2.0, 0.0, 0.0)
    );
    // l = 1, 1, 2, 2: mean 1.5, s = sqrt(4 * 0.25 / 3) = sqrt(1/3).
    assert!((r.l_mean_mm - 1.5).abs() < 1e-15);
    assert!((r.l_std_mm - (1.0f64 / 3.0).sqrt()).abs() < 1e-15);
    assert!((r.rp_mm - (1.5 + 3.0 * (1.0f64 / 3.0).sqrt())).abs() < 1e-14);
    assert!((r.rp_mm - 3.232_050_807_568_877).abs() < 1e-12);
    assert_eq!(r.n, 4);
    assert!(r.orientation.is_none() && r.drift.is_none() && r.pass.is_none());
}

#[test]
fn ap_components_signed() {
    let mut p = pose1();
    p.commanded = at(3.0, -1.0, 0.5);
    let r = evaluate_pose(&p, &TrackerMpe::default(), &ORIGIN_BELOW, None).unwrap();
    assert_eq!((r.ap_x_mm, r.ap_y_mm, r.ap_z_mm), (-1.0, 1.0, -0.5));
    assert!((r.ap_mm - 1.5).abs() < 1e-15);
}

#[test]
fn distance_by_hand() {
    let d = evaluate_distance(&pose1(), &pose2()).unwrap();
    // D_j = 10, 10.2, 9.8, 10.4: mean 10.1, s = sqrt(0.2 / 3).
    assert!((d.commanded_mm - 10.0).abs() < 1e-15);
    assert!((d.mean_mm - 10.1).abs() < 1e-12);
    assert!((d.ad_mm - 0.1).abs() < 1e-12);
    assert!((d.rd_mm - 3.0 * (0.2f64 / 3.0).sqrt()).abs() < 1e-12);
    assert_eq!((d.from, d.to), (1, 2));
}

#[test]
fn distance_uses_common_cycles_only() {
    let mut b = pose2();
    b.samples.remove(3); // cycle 4 missing at P2: D over cycles 1..3 only
    let d = evaluate_distance(&pose1(), &b).unwrap();
    assert!((d.mean_mm - 10.0).abs() < 1e-12);
    assert!((d.rd_mm - 3.0 * 0.2).abs() < 1e-12);
}

/// Commanded near B = 90 degrees, where A and C alone are unstable; attained turned by
/// theta_j = 0.1, 0.3, 0.2, 0.2 degrees about the base x axis.
#[test]
fn orientation_as_rotations() {
    let v = [
        0.0,
        0.0,
        0.0,
        10f64.to_radians(),
        89.99f64.to_radians(),
        20f64.to_radians(),
    ];
    let rc = *pose(&v).rotation.matrix();
    let mut p = pose1();
    p.commanded = pose(&v);
    for (s, t) in p.samples.iter_mut().zip([0.1f64, 0.3, 0.2, 0.2]) {
        let rx = Rotation3::from_axis_angle(&Vector3::x_axis(), t.to_radians());
        s.rotation = Some(rx.matrix() * rc);
    }
    let o = evaluate_pose(&p, &TrackerMpe::default(), &ORIGIN_BELOW, None)
        .unwrap()
        .orientation
        .unwrap();
    assert!((o.ap_a_deg - 0.2).abs() < 1e-12, "{o:?}");
    assert!(
        o.ap_b_deg.abs() < 1e-12 && o.ap_c_deg.abs() < 1e-12,
        "{o:?}"
    );
    assert!((o.ap_angle_deg - 0.2).abs() < 1e-12);
    // s(0.1, 0.3, 0.2, 0.2) = sqrt(0.02 / 3).
    assert!(
        (o.rp_a_deg - 3.0 * (0.02f64 / 3.0).sqrt()).abs() < 1e-12,
        "{o:?}"
    );
    assert!(o.rp_b_deg.abs() < 1e-12 && o.rp_c_deg.abs() < 1e-12);
}

#[test]
fn drift_from_times() {
    // Early third (t = 0, 1 h): (1,0,0) twice: AP 1, RP 0. Late third (4 h, 5 h): (2,±1,0):
    // AP 2, RP 1 + 3 * 0 = 1.
    let pts = [
        [1.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [5.0, 5.0, 5.0],
        [-3.0, 0.0, 1.0],
        [2.0, 1.0, 0.0],
        [2.0, -1.0, 0.0],
    ];
    let mut samples: Vec<Sample> = pts
        .iter()
        .enumerate()
        .map(|(i, p)| Sample {
            time_s: Some(3600.0 * i as f64),
            ..sample(i + 1, *p)
        })
        .collect();
    samples.reverse(); // order in the file does not matter, the times do
    let p = PoseSamples {
        pose: 1,
        commanded: at(0.0, 0.0, 0.0),
        samples,
    };
    let d = evaluate_pose(&p, &TrackerMpe::default(), &ORIGIN_BELOW, None)
        .unwrap()
        .drift
        .unwrap();
    assert!((d.hours - 5.0).abs() < 1e-12);
    assert!((d.dap_mm - 1.0).abs() < 1e-12);
    assert!((d.drp_mm - 1.0).abs() < 1e-12);
}

#[test]
fn tracker_mpe_beside_rp() {
    let t = TrackerMpe::default();
    let r = evaluate_pose(&pose1(), &t, &ORIGIN_BELOW, None).unwrap();
    // G = (2,0,0) is sqrt(4 + 1e6) mm from the tracker.
    let dist = (4.0f64 + 1e6).sqrt();
    assert!((r.tracker_mpe_mm - (0.015 + 0.006 * dist / 1000.0)).abs() < 1e-15);
    assert!(!r.rp_below_tracker);
    // Attained points 1 um apart: RP far below what the tracker resolves.
    let mut tiny = pose1();
    for s in &mut tiny.samples {
        s.position *= 1e-3;
    }
    let r = evaluate_pose(&tiny, &t, &ORIGIN_BELOW, None).unwrap();
    assert!(r.rp_mm < 0.004 && r.rp_below_tracker);
}

#[test]
fn spec_pass_fail() {
    let poses = [pose1(), pose2()];
    let t = TrackerMpe::default();
    let o = Vector3::zeros();
    // Both poses: AP 2, RP 3.232.
    let pass = Spec::parse("ap=2.5,rp=3.3").unwrap();
    let fail_rp = Spec::parse("rp=3, ap=2.5").unwrap();
    let fail_ap = Spec::parse("ap=1.99").unwrap();
    assert_eq!(
        evaluate(&poses, &t, &o, Some(&pass)).unwrap().pass,
        Some(true)
    );
    let e = evaluate(&poses, &t, &o, Some(&fail_rp)).unwrap();
    assert_eq!(e.pass, Some(false));
    assert!(e.poses.iter().all(|p| p.pass == Some(false)));
    assert_eq!(
        evaluate(&poses, &t, &o, Some(&fail_ap)).unwrap().pass,
        Some(false)
    );
    let e = evaluate(&poses, &t, &o, None).unwrap();
    assert_eq!(e.pass, None);
    assert_eq!((e.distance.from, e.distance.to), (1, 2));
    assert_eq!(e.distances.len(), 1);
}

#[test]
fn spec_and_tracker_parsing() {
    for bad in [
        "",
        "ap",
        "ap=x",
        "foo=1",
        "ap=-1",
        "ap=0",
        "ap=1,ap=2",
        "rp=inf",
    ] {
        let e = Spec::parse(bad).unwrap_err().to_string();
        assert!(e.starts_with("spec:"), "{bad}: {e}");
    }
    assert_eq!(
        Spec::parse("ap=0.5").unwrap(),
        Spec {
            ap_mm: Some(0.5),
            rp_mm: None
        }
    );
    assert_eq!(TrackerMpe::parse("0.01").unwrap().per_m_mm, 0.0);
    assert_eq!(TrackerMpe::parse("0.01,0.005").unwrap().per_m_mm, 0.005);
    for bad in ["x", "0.01,0.1,1", "-0.01", "5"] {
        assert!(TrackerMpe::parse(bad).is_err(), "{bad}");
    }
}

#[test]
fn too_few_samples() {
    let mut p = pose1();
    p.samples.truncate(1);
    let e = evaluate_pose(&p, &TrackerMpe::default(), &ORIGIN_BELOW, None).unwrap_err();
    assert!(e.to_string().contains("pose P1"), "{e}");
}
