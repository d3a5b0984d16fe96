/// Settings are checked before any work: a parameter given to both --fix and --free is refused
/// before the data file is read (this one is not even a measurement file), and nothing is
/// written.
#[test]
fn calibrate_checks_its_settings_before_reading_the_data() {
    let dir = tempfile::tempdir().unwrap();
    let data = dir.path().join("data.csv");
    std::fs::write(&data, "not,a,measurement,file\n").unwrap();
    let out = dir.path().join("r.json");
    let args = [
        "calibrate",
        "--robot",
        "kuka-kr480-r3330",
        "--data",
        data.to_str().unwrap(),
        "--fix",
        "d2,a4",
        "--free",
        "d2",
        "--out",
        out.to_str().unwrap(),
    ];
    fails(
        &args,
        3,
        &["--fix: `d2` is given both to --fix and to --free"],
    );
    assert!(!stderr(&robocal(&args)).contains("data.csv"));
    assert!(!out.exists());
}
