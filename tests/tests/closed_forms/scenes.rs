//! The scenes of the closed-form tests, each twinned with its `.mech` text (to inspect its plan):
//! one per group kind, a slider-crank pushed by its slider to dead centre, and a six-bar whose
//! class III group has no closed form. Every dimension, the drive and the assembly guesses are
//! parameters, so that a test picks the geometry and the branch at run time.

use mechgen_tests::twin;

twin! {
    pub FOUR_BAR,
    /// A four-bar (crank `a`, coupler `b`, rocker `c`, frame `d`): one RRR dyad, the block
    /// (coupler.theta, rocker.theta) whose rows are the rocker pin's x and y (CircleCircle).
    /// The coupler and rocker guesses pick the branch.
    pub mechanism FourBar {
        param a = 40;
        param b = 120;
        param c = 80;
        param d = 100;
        param omega = 10;
        param phase = 0;
        param coupler_guess = 0.6;
        param rocker_guess = 1.1;

        ground frame at (0, 0, 0);
        body crank near (0, 0, phase);
        body coupler near (a * cos(phase), a * sin(phase), coupler_guess);
        body rocker near (d, 0, rocker_guess);

        joint crank_pivot: revolute(frame, crank);
        joint crank_pin: revolute(crank @ (a, 0), coupler);
        joint rocker_pin: revolute(coupler @ (b, 0), rocker @ (c, 0));
        joint rocker_pivot: revolute(rocker, frame @ (d, 0));

        driver turn: angle(crank) = omega * t + phase;
    }
}

twin! {
    pub OFFSET_SLIDER,
    /// An offset slider-crank (crank `r`, rod `l`, guide `e` above the pivot): the 1×1 block
    /// rod.theta (CircleLine). The rod guess picks the slider's side.
    pub mechanism OffsetSlider {
        param r = 30;
        param l = 80;
        param e = 12;
        param omega = 10;
        param phase = 0.5;
        param rod_guess = -0.2;

        ground frame at (0, 0, 0);
        body crank near (0, 0, phase);
        body rod near (r * cos(phase), r * sin(phase), rod_guess);
        body slider near (l, e, 0);

        joint pivot: revolute(frame, crank);
        joint crank_pin: revolute(crank @ (r, 0), rod);
        joint wrist_pin: revolute(rod @ (l, 0), slider);
        joint guide: prismatic(frame @ (0, e), slider, along (1, 0));

        driver turn: angle(crank) = omega * t + phase;
    }
}

twin! {
    pub PISTON_CRANK,
    /// The seed's piston-crank with its dimensions as parameters (crank pin at
    /// crank @ (0, `radius`), rod @ (`rod_pin`, 0) on it, rod @ (0, `rod_length`) at the piston
    /// pin piston @ (−`pin`, 0), the liner's axis `offset` above the bearing): the 2×2 block
    /// (rod.y, rod.theta), rod.y eliminated first (CircleLine). The rod guesses pick the
    /// piston's side.
    pub mechanism PistonCrank {
        param radius = 43;
        param rod_pin = 41.3;
        param rod_length = 102.6;
        param pin = 28;
        param offset = 0;
        param omega = 314;
        param phase = 0;
        param rod_y_guess = 72;
        param rod_guess = -2.35;

        ground liner at (0, offset, 0);
        body piston near (130, offset, 0);
        body rod near (29, rod_y_guess, rod_guess);
        body crank near (0, 0, phase);
        ground bearing at (0, 0, 0);

        joint crank_pin: revolute(rod @ (rod_pin, 0), crank @ (0, radius));
        joint piston_pin: revolute(piston @ (-pin, 0), rod @ (0, rod_length));
        joint main_bearing: revolute(crank, bearing);
        joint slide: prismatic(liner, piston, along (1, 0));

        driver crank_angle: angle(crank) = omega * t + phase;
    }
}

twin! {
    pub COLLAR,
    /// A collar on a swinging arm, its x driven: the 1×1 block collar.y, whose coefficient
    /// cos θ_arm comes from an earlier stage (Linear). The sleeve's point on the arm, `size`
    /// out, sets the scene's length scale.
    pub mechanism Collar {
        param size = 4;
        param phase = 0.3;
        param swing = 0.8;
        param omega = 2;
        param reach = 2;
        param stroke = 0.5;
        param nu = 3;

        ground frame at (0, 0, 0);
        body arm near (0, 0, phase);
        body collar near (reach, reach * tan(phase), phase);

        joint pivot: revolute(frame, arm);
        joint sleeve: prismatic(arm @ (size, 0), collar, along (1, 0));

        driver turn: angle(arm) = phase + swing * sin(omega * t);
        driver push: x(collar) = reach + stroke * sin(nu * t);
    }
}

twin! {
    pub PUSHED_SLIDER,
    /// An in-line slider-crank driven by its slider (at `start + speed * t`), the rod's
    /// reference point at the wrist pin: the block (crank.theta, rod.theta), the crank pin's x
    /// and y (CircleCircle), with dead centres at slider positions r + l and l − r.
    pub mechanism PushedSlider {
        param r = 1;
        param l = 3;
        param start = 3.5;
        param speed = 1;
        param crank_guess = 0.5;
        param rod_guess = -0.2;

        ground frame at (0, 0, 0);
        body crank near (0, 0, crank_guess);
        body rod near (start, 0, rod_guess);
        body slider near (start, 0, 0);

        joint pivot: revolute(frame, crank);
        joint crank_pin: revolute(crank @ (r, 0), rod @ (-l, 0));
        joint wrist_pin: revolute(rod, slider);
        joint guide: prismatic(frame, slider, along (1, 0));

        driver push: x(slider) = start + speed * t;
    }
}

twin! {
    pub SIX_BAR,
    /// A crank driving a class III Assur group (a ternary link held by three binary links: its
    /// loop does not split into dyads, a 6×6 Newton block), followed by an RRR dyad hung from
    /// the ternary link (a CircleCircle block). The three binary links lie along three
    /// non-concurrent lines, so the group stays regular over a whole turn of the crank.
    pub mechanism SixBar {
        param omega = 1;
        param crank = 0.5;
        param side = sqrt(2.6^2 + 1.5^2);
        param upper = sqrt(1.5^2 + 3^2);
        param lower = sqrt(2 * 2.5^2);

        ground frame at (0, 0, 0);
        body driver near (0, 0, 0);
        body link1 near (0.5, 0, 1.5707963267948966);
        body link2 near (7.1, 4.5, atan2(-1.5, -2.6));
        body link3 near (-0.1, 7.5, atan2(-1.5, 2.6));
        body ternary near (0.5, 3, 0);
        body arm near (4.5, 6, atan2(3, 1.5));
        body lever near (8.5, 6.5, atan2(2.5, -2.5));

        joint pivot: revolute(frame, driver);
        joint crank_pin: revolute(driver @ (crank, 0), link1);
        joint first: revolute(link1 @ (3, 0), ternary);
        joint second: revolute(link2 @ (side, 0), ternary @ (4, 0));
        joint second_pivot: revolute(link2, frame @ (7.1, 4.5));
        joint third: revolute(link3 @ (side, 0), ternary @ (2, 3));
        joint third_pivot: revolute(link3, frame @ (-0.1, 7.5));
        joint arm_pin: revolute(arm, ternary @ (4, 3));
        joint elbow: revolute(arm @ (upper, 0), lever @ (lower, 0));
        joint lever_pivot: revolute(lever, frame @ (8.5, 6.5));

        driver turn: angle(driver) = omega * t;
    }
}
