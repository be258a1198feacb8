//! The CLI exits non-zero on a closed-form stage whose result breaks the acceptance rule (scaled
//! residual above `acceptance_tolerance`), saying it cannot be resolved. The rule itself, in
//! generated code, the interpreter and the dense reference, is tested on the same three scenes
//! in `tests/tests/acceptance.rs`.

/// A bracket welded at 30° to a driven arm: every coordinate in closed form.
const WELDED: &str = r"
mechanism Welded {
    param w = 1;
    ground frame at (0, 0, 0);
    body arm near (0, 0, 0);
    body bracket near (10, 0, 0.5);
    joint pivot: revolute(frame, arm);
    joint fix: weld(arm @ (10, 0), bracket, angle 30deg);
    driver spin: angle(arm) = w * t;
}";

/// Two gears with a phase, the first driven.
const GEARED: &str = r"
mechanism Geared {
    param w = 1;
    ground frame at (0, 0, 0);
    body a near (0, 0, 0);
    body b near (50, 0, 0);
    joint pa: revolute(frame, a);
    joint pb: revolute(frame @ (50, 0), b);
    joint mesh: gear(a, b, ratio -2, phase 0.1);
    driver spin: angle(a) = w * t;
}";

/// A rack and pinion with a phase, the pinion driven.
const RACKED: &str = r"
mechanism Racked {
    param w = 1;
    ground frame at (0, 0, 0);
    body pinion near (0, 0, 0);
    body bar near (0, -10, 0);
    joint pivot: revolute(frame, pinion);
    joint slide: prismatic(frame @ (0, -10), bar, along (1, 0));
    joint teeth: rack(slide, pinion, ratio 3.3, phase 0.7);
    driver spin: angle(pinion) = w * t;
}";

#[test]
fn the_cli_exits_non_zero_above_acceptance() {
    let dir = std::env::temp_dir().join(format!("mechgen-acceptance-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    for (name, source) in [("weld", WELDED), ("gear", GEARED), ("rack", RACKED)] {
        let path = dir.join(format!("{name}.mech"));
        std::fs::write(&path, source).unwrap();
        for (w, fails) in [("1", false), ("1e20", true)] {
            let args = ["solve", path.to_str().unwrap(), "--at", "0,1", "--set"];
            let args = args
                .iter()
                .map(|a| a.into())
                .chain([format!("w={w}").into()]);
            let (mut out, mut err) = (Vec::new(), Vec::new());
            let code = mechgen_cli::run(args, &mut out, &mut err);
            let err = String::from_utf8_lossy(&err);
            assert_eq!(code != 0, fails, "{name}, w = {w}: {err}");
            if fails {
                assert!(err.contains("cannot be resolved"), "{err}");
            }
        }
    }
    std::fs::remove_dir_all(&dir).unwrap();
}
