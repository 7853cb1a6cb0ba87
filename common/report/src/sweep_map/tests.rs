use super::*;
use crate::plots::looks::svg;
use crate::plots::WIDTH;
use crate::sweep::axis;

fn means(swing: f64, w: f64, ratio: f64) -> Vec<(Option<f64>, Option<f64>)> {
    let mut m = vec![(None, None); METRICS.len()];
    let mut put = |name, v| m[metric(name).expect("a metric")] = (Some(v), None);
    put("force_swing_n", swing);
    put("observer_min_j", w);
    put("stiffness_ratio", ratio);
    m
}

fn read(p: &Path) -> String {
    std::fs::read_to_string(p).expect("svg")
}

/// Each two-point `<polyline>` of stroke width 2 in `colour`: its two ends.
fn strokes(svg: &str, colour: &str) -> Vec<[(i32, i32); 2]> {
    svg.split("<polyline")
        .skip(1)
        .filter(|el| {
            el.contains(&format!("stroke=\"{colour}\"")) && el.contains("stroke-width=\"2\"")
        })
        .filter_map(|el| {
            let pts = el.split("points=\"").nth(1)?.split('"').next()?;
            let p: Vec<(i32, i32)> = pts
                .split_whitespace()
                .filter_map(|p| {
                    let (x, y) = p.split_once(',')?;
                    Some((x.parse().ok()?, y.parse().ok()?))
                })
                .collect();
            (p.len() == 2).then(|| [p[0], p[1]])
        })
        .collect()
}

/// The filled black or white `<rect>`s at least five times as wide as high: the
/// bars (x, y, width).
fn bars(svg: &str) -> Vec<(i32, i32, i32)> {
    svg.split("<rect")
        .skip(1)
        .filter_map(|el| {
            let el = el.split('>').next()?;
            let attr = |name: &str| svg::int_attr(el, name);
            let ink = el.contains("fill=\"#000000\"") || el.contains("fill=\"#FFFFFF\"");
            let (w, h) = (attr("width")?, attr("height")?);
            (ink && w >= 5 * h).then_some((attr("x")?, attr("y")?, w))
        })
        .collect()
}

#[test]
fn a_cell_says_whether_the_contact_settled_and_the_channel_made_energy() {
    let c = cell(&means(0.1, -0.01, 0.9));
    assert_eq!(
        (c.settled, c.passive, c.ratio),
        (Some(true), Some(true), Some(0.9))
    );
    assert_eq!(cell(&means(2.0, -0.01, 0.9)).settled, Some(false));
    assert_eq!(cell(&means(0.1, -0.2, 0.9)).passive, Some(false));
    let none = vec![(None, None); METRICS.len()];
    let empty = Cell {
        ratio: None,
        settled: None,
        passive: None,
    };
    assert_eq!(cell(&none), empty);
}

#[test]
fn the_colour_runs_from_blue_through_white_to_red() {
    assert_eq!(colour(Some(0.0)), RGBColor(49, 54, 149));
    assert_eq!(colour(Some(0.5)), RGBColor(247, 247, 247));
    assert_eq!(colour(Some(1.0)), RGBColor(215, 48, 39));
    assert_eq!(colour(None), RGBColor(200, 200, 200));
    assert_eq!(colour(Some(9.0)), RGBColor(103, 0, 13));
}

/// White on the dark blue and the dark red, black on white, on grey and on the red
/// of a wall felt whole.
#[test]
fn a_number_is_written_in_the_colour_that_contrasts_with_its_cell() {
    let white = RGBColor(255, 255, 255);
    let black = RGBColor(0, 0, 0);
    assert_eq!(ink(colour(Some(0.0))), white);
    assert_eq!(ink(colour(Some(RATIO_TOP))), white);
    assert_eq!(ink(colour(Some(0.5))), black);
    assert_eq!(ink(colour(None)), black);
    assert_eq!(ink(colour(Some(1.0))), black);
}

/// The points of a 2 x 2 x 2 sweep: the contact unsettled without control at the
/// second delay, the channel making energy with mmt at the last cell.
fn points() -> Vec<crate::sweep_plots::Point> {
    let mut points = Vec::new();
    for (i, j, k) in (0..2).flat_map(|i| (0..2).flat_map(move |j| (0..2).map(move |k| (i, j, k)))) {
        let unstable = k == 0 && j == 1;
        let swing = if unstable { 5.0 } else { 0.0 };
        let w = if k == 1 && i == 1 && j == 1 {
            -0.1
        } else {
            -0.001
        };
        points.push((
            vec![i, j, k, 0],
            means(swing, w, 0.25 + 0.25 * (i + j + k) as f64),
        ));
    }
    points
}

fn axes() -> [Axis; 4] {
    [
        axis("environment.objects[0].stiffness=[300,300,300],[600,600,600]").expect("x"),
        axis("network.forward.delay_ms=0,200").expect("y"),
        axis("control.kind=none,mmt").expect("z"),
        axis("network.backward.delay=[0,0,0]").expect("fixed"),
    ]
}

/// Two numeric keys and a third: one map per value of the third, each cell its
/// ratio, a cross on each unstable one, a bar where the channel made energy; a key
/// of one value in the subtitle; words on the first axis: no map.
#[test]
fn a_map_per_value_of_the_third_axis() {
    let tmp = tempfile::tempdir().expect("tmp");
    let dir = tmp.path();
    let files = sweep_maps(dir, &axes(), &points()).expect("maps");
    assert_eq!(files, ["map-none.svg", "map-mmt.svg"]);
    let none = read(&dir.join("map-none.svg"));
    let mmt = read(&dir.join("map-mmt.svg"));
    for s in [&none, &mmt] {
        let texts: Vec<String> = svg::placed(s).into_iter().map(|t| t.0).collect();
        for want in [
            "network.forward.delay_ms (ms)",
            "environment.objects[0].stiffness (N/m)",
            "network.backward.delay=[0,0,0] samples",
            // The ticks at the cells, as numbers.
            "300",
            "600",
            "0",
            "200",
        ] {
            assert!(texts.iter().any(|t| t == want), "{want}: {texts:?}");
        }
    }
    assert!(none.contains("felt / environment stiffness, control.kind=none"));
    // Two crossed cells on none's map (four strokes each), none on mmt's; one bar (a
    // filled rectangle in the cell's ink) on mmt's, none on none's; the legend's
    // cross (two strokes) and bar on each.
    let crosses = |s: &str| strokes(s, "#000000").len() + strokes(s, "#FFFFFF").len();
    assert_eq!((crosses(&none), crosses(&mmt)), (8 + 2, 2), "{none}");
    let bars = |s: &str| bars(s).len();
    assert_eq!((bars(&none), bars(&mmt)), (1, 1 + 1), "{mmt}");
    assert!(
        mmt.contains("\n1.00\n") && none.contains("\n0.25\n"),
        "{mmt}"
    );
    let words = [
        axis("control.kind=none,mmt").expect("a"),
        axis("seed=1,2").expect("b"),
    ];
    assert!(sweep_maps(dir, &words, &points()).expect("none").is_empty());
}

/// The cross of an unsettled cell stops short of the cell's number: no stroke
/// passes through the number's box.
#[test]
fn the_cross_leaves_the_number_readable() {
    let tmp = tempfile::tempdir().expect("tmp");
    sweep_maps(tmp.path(), &axes(), &points()).expect("maps");
    let text = read(&tmp.path().join("map-none.svg"));
    let numbers: Vec<(String, i32, i32)> = svg::placed(&text)
        .into_iter()
        .filter(|t| t.0.len() == 4 && t.0.parse::<f64>().is_ok() && t.1 < WIDTH as i32 - 150)
        .collect();
    assert_eq!(numbers.len(), 4, "{numbers:?}");
    let strokes: Vec<_> = ["#000000", "#FFFFFF"]
        .iter()
        .flat_map(|c| strokes(&text, c))
        .collect();
    assert_eq!(strokes.len(), 8 + 2, "two cells' crosses and the legend's");
    for (n, x, y) in &numbers {
        // The number's box, about: 16 px type, 10 px a character.
        let inside = |p: (i32, i32)| (p.0 - x).abs() < 20 && (p.1 - y).abs() < 8;
        for s in &strokes {
            let mid = ((s[0].0 + s[1].0) / 2, (s[0].1 + s[1].1) / 2);
            assert!(
                !inside(s[0]) && !inside(s[1]) && !inside(mid),
                "a stroke {s:?} through {n} at ({x}, {y})"
            );
        }
    }
}

/// The colour bar stands beside the map: its steps from the lowest ratio's blue to
/// the darkest red, its ticks 0 to 1.5 and its title.
#[test]
fn a_map_has_its_colour_bar() {
    let tmp = tempfile::tempdir().expect("tmp");
    sweep_maps(tmp.path(), &axes(), &points()).expect("maps");
    let text = read(&tmp.path().join("map-mmt.svg"));
    let hex = |c: RGBColor| format!("fill=\"#{:02X}{:02X}{:02X}\"", c.0, c.1, c.2);
    let steps = (0..60).filter(|k| {
        let r = (*k as f64 + 0.5) * RATIO_TOP / 60.0;
        text.contains(&hex(colour(Some(r))))
    });
    assert_eq!(steps.count(), 60);
    let texts: Vec<(String, i32, i32)> = svg::placed(&text);
    let bar: Vec<&(String, i32, i32)> = texts.iter().filter(|t| t.1 > WIDTH as i32 - 150).collect();
    let labels: Vec<&str> = bar.iter().map(|t| t.0.as_str()).collect();
    assert_eq!(
        labels,
        [
            "0",
            "0.25",
            "0.5",
            "0.75",
            "1",
            "1.25",
            "≥1.5",
            "felt / environment stiffness"
        ]
    );
    // From the bottom up.
    assert!(bar.windows(2).take(6).all(|w| w[0].2 > w[1].2), "{bar:?}");
}

/// A fourth key that varies: a map per combination of the third and the fourth,
/// each cell its own combination's.
#[test]
fn a_map_per_combination_of_the_later_keys() {
    let axes = [
        axis("environment.objects[0].stiffness=300,600").expect("x"),
        axis("network.forward.delay_ms=0,200").expect("y"),
        axis("control.kind=none,mmt").expect("z"),
        axis("seed=1,2").expect("w"),
    ];
    let points: Vec<crate::sweep_plots::Point> = crate::sweep::combinations(&axes)
        .into_iter()
        .map(|c| {
            let ratio = 0.1 * (1 + c[2] * 2 + c[3]) as f64;
            (c, means(0.0, 0.0, ratio))
        })
        .collect();
    let tmp = tempfile::tempdir().expect("tmp");
    let files = sweep_maps(tmp.path(), &axes, &points).expect("maps");
    assert_eq!(
        files,
        [
            "map-none-1.svg",
            "map-none-2.svg",
            "map-mmt-1.svg",
            "map-mmt-2.svg"
        ]
    );
    for (file, want) in files.iter().zip(["0.10", "0.20", "0.30", "0.40"]) {
        let text = read(&tmp.path().join(file));
        let cells = svg::placed(&text)
            .into_iter()
            .filter(|t| t.0 == want)
            .count();
        assert_eq!(cells, 4, "{file}: every cell {want}");
    }
}
