//! `fourfold critical` through the binary: the table and the JSON list say the same proved
//! values, and bad requests are usage errors that name the flag.

mod common;

use common::fourfold;

const SPHERITORUS: &str = "(sqrt(x^2+y^2+z^2)-R)^2+w^2-r^2";

#[test]
fn critical_lists_the_spheritorus_s_four_proved_values() {
    let base = [
        "critical",
        SPHERITORUS,
        "--param",
        "R=1",
        "--param",
        "r=0.4",
        "--angles",
        "1.3,0.2,-0.7,0.4,0.1,2.1",
    ];
    let (code, stdout, stderr) = fourfold(&base);
    assert_eq!(code, Some(0), "{stderr}");
    for (index, meaning) in [
        ("0", "a component is born"),
        ("1", "two pieces join, or a tunnel opens"),
        ("2", "a tunnel closes, or a piece splits"),
        ("3", "a component vanishes"),
    ] {
        let line = stdout
            .lines()
            .find(|l| l.contains(meaning))
            .unwrap_or_else(|| panic!("no '{meaning}' in {stdout}"));
        assert!(
            line.contains(&format!(" {index} ")) && line.contains("proved"),
            "{line}"
        );
    }
    assert!(stdout.contains("0 undecided"), "{stdout}");

    let mut json_args = base.to_vec();
    json_args.push("--json");
    let (code, stdout, stderr) = fourfold(&json_args);
    assert_eq!(code, Some(0), "{stderr}");
    let list: serde_json::Value = serde_json::from_str(&stdout).unwrap();
    let list = list.as_array().unwrap();
    assert_eq!(list.len(), 4, "{stdout}");
    let values: Vec<[f64; 2]> = list
        .iter()
        .map(|p| serde_json::from_value(p["value"].clone()).unwrap())
        .collect();
    // ±R|a| ± r, with |a| the length of n2's xyz part.
    let a = values[3][0] - 0.4;
    for (v, exact) in values.iter().zip([-a - 0.4, -a + 0.4, a - 0.4, a + 0.4]) {
        assert!(
            v[0] <= v[1] && (v[0] - exact).abs() < 1e-9,
            "{v:?} against {exact}"
        );
    }
    for (k, p) in list.iter().enumerate() {
        assert_eq!(p["index"], k, "{p}");
        assert_eq!(p["status"], "proved");
        assert_eq!(p["point"].as_array().unwrap().len(), 4);
    }
}

#[test]
fn degenerate_values_have_no_index() {
    let (code, stdout, stderr) =
        fourfold(&["critical", "x^2+y^2+w^2-1", "--json", "--no-boundary"]);
    assert_eq!(code, Some(0), "{stderr}");
    let list: serde_json::Value = serde_json::from_str(&stdout).unwrap();
    let list = list.as_array().unwrap();
    assert_eq!(list.len(), 2, "{stdout}");
    for p in list {
        assert_eq!(p["status"], "degenerate");
        assert!(p["index"].is_null());
    }
}

#[test]
fn bad_critical_requests_name_the_flag() {
    for (args, said) in [
        (vec!["--max-level", "20"], "--max-level 20"),
        (vec!["--max-level", "1"], "--max-level 1"),
        (vec!["--budget", "0"], "--budget 0"),
        (vec!["--angles", "1,2"], "--angles"),
        (vec!["--domain", "1,0,-1,1,-1,1,-1,1"], "domain"),
    ] {
        let mut argv = vec!["critical", "x^2+y^2+z^2+w^2-1"];
        argv.extend(args.iter());
        let (code, stdout, stderr) = fourfold(&argv);
        assert_eq!(code, Some(2), "{args:?}: {stderr}");
        assert!(stderr.contains(said), "{args:?}: {stderr}");
        assert!(stdout.is_empty());
    }
}

#[test]
fn a_slice_sweep_says_which_frames_straddle_each_critical_value() {
    let dir = std::env::temp_dir().join("fourfold-critical-sweep");
    std::fs::create_dir_all(&dir).unwrap();
    let out = dir.join("sweep.gif");
    // Frames at -1.5, -1.25, ..., 1.5; the glome's poles are at ±1 exactly, where frames 3
    // and 11 would fall: those move off them.
    let (code, stdout, stderr) = fourfold(&[
        "animate",
        "x^2+y^2+z^2+w^2-1",
        "--slice-sweep",
        "-1.5..1.5",
        "--frames",
        "13",
        "--size",
        "32x32",
        "--cpu",
        "-o",
        out.to_str().unwrap(),
    ]);
    assert_eq!(code, Some(0), "{stderr}");
    let straddles: Vec<&str> = stdout.lines().filter(|l| l.contains("straddle")).collect();
    assert_eq!(straddles.len(), 2, "{stdout}");
    assert!(
        straddles[0].starts_with("frames 2 and 3 straddle c = -1.000000")
            || straddles[0].starts_with("frames 3 and 4 straddle c = -1.000000"),
        "{stdout}"
    );
    assert!(straddles[0].contains("a component is born"), "{stdout}");
    assert!(straddles[1].contains("a component vanishes"), "{stdout}");
}
