//! Hostile STEP files of the adversarial round (issue 35), generated here: each gets a named
//! error or a correct result, within budgets checked by counting the reader's work
//! (`Report::work`), never by timing.

use kerf_step::{check_syntax, import, ImportOptions, StepError};

fn file(data: &str) -> String {
    format!(
        "ISO-10303-21;\nHEADER;\nFILE_SCHEMA(('AUTOMOTIVE_DESIGN'));\nENDSEC;\nDATA;\n{data}ENDSEC;\nEND-ISO-10303-21;\n"
    )
}

const MM: &str = "#900=(LENGTH_UNIT()NAMED_UNIT(*)SI_UNIT(.MILLI.,.METRE.));\n\
#901=(NAMED_UNIT(*)PLANE_ANGLE_UNIT()SI_UNIT($,.RADIAN.));\n\
#902=(GEOMETRIC_REPRESENTATION_CONTEXT(3)GLOBAL_UNIT_ASSIGNED_CONTEXT((#900,#901))REPRESENTATION_CONTEXT('',''));\n";

/// A trimmed line from (0,0,0) along x, parameters 0..10, with a vector magnitude.
fn line(id: u64, magnitude: &str, t2: &str) -> String {
    format!(
        "#{a}=CARTESIAN_POINT('',(0.,0.,0.));\n#{b}=DIRECTION('',(1.,0.,0.));\n#{c}=VECTOR('',#{b},{magnitude});\n\
         #{d}=LINE('',#{a},#{c});\n#{id}=TRIMMED_CURVE('',#{d},(PARAMETER_VALUE(0.)),(PARAMETER_VALUE({t2})),.T.,.PARAMETER.);\n",
        a = id + 1,
        b = id + 2,
        c = id + 3,
        d = id + 4
    )
}

/// A "billion laughs" DAG: level k is a composite of `fan` segments all pointing at level k-1.
fn laughs(fan: usize, depth: usize) -> String {
    let mut t = String::from(MM);
    t += &line(1, "1.", "10.");
    let mut below = 1u64;
    let mut next = 100u64;
    for _ in 0..depth {
        let seg = next;
        t += &format!("#{seg}=COMPOSITE_CURVE_SEGMENT(.CONTINUOUS.,.T.,#{below});\n");
        let list = vec![format!("#{seg}"); fan].join(",");
        t += &format!("#{}=COMPOSITE_CURVE('',({list}),.F.);\n", seg + 1);
        below = seg + 1;
        next += 2;
    }
    t += &format!("#99=GEOMETRIC_CURVE_SET('cut',(#{below}));\n");
    file(&t)
}

#[test]
fn a_composite_dag_is_refused_at_once_naming_the_repeated_segment() {
    for (fan, depth) in [(4, 16), (3, 12), (2, 2)] {
        let e = import(&laughs(fan, depth), &ImportOptions::default()).unwrap_err();
        let msg = e.to_string();
        assert!(
            matches!(e, StepError::Entity { .. }) && msg.contains("already used"),
            "fan {fan} depth {depth}: {msg}"
        );
        assert!(
            msg.len() < 2000,
            "the message stays short: {} bytes",
            msg.len()
        );
    }
}

#[test]
fn huge_magnitudes_trims_and_units_are_named_errors_not_panics() {
    let cases = [
        file(&format!("{MM}{}#99=GEOMETRIC_CURVE_SET('',(#1));\n", line(1, "1.E308", "10."))),
        file(&format!("{MM}{}#99=GEOMETRIC_CURVE_SET('',(#1));\n", line(1, "1.", "1.7E308"))),
        file(&format!(
            "#900=(CONVERSION_BASED_UNIT('big',#903)LENGTH_UNIT()NAMED_UNIT(*));\n\
             #903=LENGTH_MEASURE_WITH_UNIT(LENGTH_MEASURE(1.E300),#904);\n\
             #904=(LENGTH_UNIT()NAMED_UNIT(*)SI_UNIT(.MILLI.,.METRE.));\n\
             #902=(GEOMETRIC_REPRESENTATION_CONTEXT(3)GLOBAL_UNIT_ASSIGNED_CONTEXT((#900))REPRESENTATION_CONTEXT('',''));\n\
             {}#99=GEOMETRIC_CURVE_SET('',(#1));\n",
            line(1, "1.", "10.")
        )),
    ];
    for (k, text) in cases.iter().enumerate() {
        let e = import(text, &ImportOptions::default()).unwrap_err();
        assert!(
            matches!(e, StepError::Entity { .. }),
            "case {k}: an entity named: {e}"
        );
    }
}

#[test]
fn units_must_measure_what_they_are_used_for() {
    let with_units = |units: &str| {
        file(&format!(
            "{units}#902=(GEOMETRIC_REPRESENTATION_CONTEXT(3)GLOBAL_UNIT_ASSIGNED_CONTEXT((#900,#901))REPRESENTATION_CONTEXT('',''));\n{}#99=GEOMETRIC_CURVE_SET('',(#1));\n",
            line(1, "1.", "10.")
        ))
    };
    let mm = "#900=(LENGTH_UNIT()NAMED_UNIT(*)SI_UNIT(.MILLI.,.METRE.));\n";
    let rad = "#901=(NAMED_UNIT(*)PLANE_ANGLE_UNIT()SI_UNIT($,.RADIAN.));\n";
    // An angle unit declared as kilometres, a length unit of radians, a prefix as a string.
    for (units, needle) in [
        (
            format!("{mm}#901=(NAMED_UNIT(*)PLANE_ANGLE_UNIT()SI_UNIT(.KILO.,.METRE.));\n"),
            "based on the radian",
        ),
        (
            format!("#900=(LENGTH_UNIT()NAMED_UNIT(*)SI_UNIT($,.RADIAN.));\n{rad}"),
            "based on the metre",
        ),
        (
            format!("#900=(LENGTH_UNIT()NAMED_UNIT(*)SI_UNIT('MILLI',.METRE.));\n{rad}"),
            "enumeration",
        ),
    ] {
        let e = import(&with_units(&units), &ImportOptions::default())
            .unwrap_err()
            .to_string();
        assert!(e.contains(needle), "{e}");
    }
    // The good units read 10 mm.
    let ok = import(
        &with_units(&format!("{mm}{rad}")),
        &ImportOptions::default(),
    )
    .expect("reads");
    assert!(ok.report.warnings.is_empty(), "{:?}", ok.report.warnings);
    assert_eq!(ok.file.curves[0].control_points[1][0], 10.0);
    // No unit context at all: read as mm, and said.
    let bare = file(&format!(
        "{}#99=GEOMETRIC_CURVE_SET('',(#1));\n",
        line(1, "1.", "10.")
    ));
    let r = import(&bare, &ImportOptions::default()).expect("reads as mm");
    assert!(
        r.report.warnings.iter().any(|w| w.contains("read as mm")),
        "{:?}",
        r.report.warnings
    );
}

#[test]
fn a_curve_in_two_sets_is_taken_once() {
    let t = file(&format!(
        "{MM}{}#98=GEOMETRIC_CURVE_SET('a',(#1));\n#99=GEOMETRIC_CURVE_SET('b',(#1,#1));\n",
        line(1, "1.", "10.")
    ));
    let r = import(&t, &ImportOptions::default()).expect("reads");
    assert_eq!(r.file.curves.len(), 1, "one contour");
    assert_eq!(
        r.report
            .skipped
            .iter()
            .filter(|s| s.contains("taken once"))
            .count(),
        2
    );
}

/// Unused points cost the index, not parsed values: the reader parses the file once for its
/// syntax and touches only what the contour reaches.
#[test]
fn unused_entities_are_indexed_not_kept() {
    let mut t = String::from(MM);
    t += &line(1, "1.", "10.");
    t += "#99=GEOMETRIC_CURVE_SET('',(#1));\n";
    for k in 0..100_000u64 {
        t += &format!("#{}=CARTESIAN_POINT('',(1.,2.,3.));\n", 10_000 + k);
    }
    let text = file(&t);
    assert_eq!(check_syntax(&text).expect("valid"), 100_000 + 9);
    let r = import(&text, &ImportOptions::default()).expect("reads");
    assert_eq!(r.report.work.instances, 100_009);
    assert_eq!(
        r.report.work.curve_points, 0,
        "a line has no B-spline poles"
    );
    assert_eq!(r.report.work.segments, 1);
}

#[test]
fn long_input_is_not_echoed_in_errors() {
    let word = "A".repeat(5_000_000);
    let text = format!("ISO-10303-21;\nHEADER;\nENDSEC;\n{word};\n");
    let e = import(&text, &ImportOptions::default())
        .unwrap_err()
        .to_string();
    assert!(e.len() < 300, "{} bytes of message", e.len());
}

/// A face whose loop repeats one edge thousands of times is refused after one edge's work.
#[test]
fn a_loop_repeating_an_edge_is_refused_with_bounded_work() {
    let mut t = String::from(MM);
    t += "#10=CARTESIAN_POINT('',(0.,0.,0.));\n#11=DIRECTION('',(0.,0.,1.));\n#12=DIRECTION('',(1.,0.,0.));\n\
          #13=AXIS2_PLACEMENT_3D('',#10,#11,#12);\n#14=PLANE('',#13);\n#15=CIRCLE('',#13,5.);\n\
          #16=CARTESIAN_POINT('',(5.,0.,0.));\n#17=VERTEX_POINT('',#16);\n\
          #18=EDGE_CURVE('',#17,#17,#15,.T.);\n#19=ORIENTED_EDGE('',*,*,#18,.T.);\n";
    let list = vec!["#19"; 10_000].join(",");
    t += &format!("#20=EDGE_LOOP('',({list}));\n#21=FACE_OUTER_BOUND('',#20,.T.);\n#22=ADVANCED_FACE('',(#21),#14,.T.);\n");
    let r = import(&file(&t), &ImportOptions::default().with_edges(None));
    let e = r.unwrap_err().to_string();
    assert!(
        e.contains("no face boundary loop") || e.contains("second time"),
        "{e}"
    );
}

#[test]
fn a_context_with_two_length_units_is_refused_whichever_comes_first() {
    // mm and inch in one context: the last listed won silently (a 25.4 x error either way).
    let inch = "#905=(CONVERSION_BASED_UNIT('INCH',#906)LENGTH_UNIT()NAMED_UNIT(*));\n\
                #906=LENGTH_MEASURE_WITH_UNIT(LENGTH_MEASURE(25.4),#900);\n";
    let mm = "#900=(LENGTH_UNIT()NAMED_UNIT(*)SI_UNIT(.MILLI.,.METRE.));\n\
              #901=(NAMED_UNIT(*)PLANE_ANGLE_UNIT()SI_UNIT($,.RADIAN.));\n";
    for order in ["#900,#905,#901", "#905,#900,#901"] {
        let text = file(&format!(
            "{mm}{inch}#902=(GEOMETRIC_REPRESENTATION_CONTEXT(3)GLOBAL_UNIT_ASSIGNED_CONTEXT(({order}))REPRESENTATION_CONTEXT('',''));\n{}#99=GEOMETRIC_CURVE_SET('',(#1));\n",
            line(1, "1.", "10.")
        ));
        let e = import(&text, &ImportOptions::default()).unwrap_err();
        assert!(
            e.to_string().contains("lists a second length unit"),
            "{order}: {e}"
        );
    }
}

#[test]
fn a_long_name_is_cut_in_the_contour_id() {
    // Ids reach every output; a 20 MB name made 140 MB of files. Kept: the first 120
    // characters, and the cut reported.
    let long = "N".repeat(10_000);
    let text = file(&format!(
        "{MM}#1=CARTESIAN_POINT('',(0.,0.,0.));\n#2=AXIS2_PLACEMENT_3D('',#1,$,$);\n#3=CIRCLE('{long}',#2,5.);\n#99=GEOMETRIC_CURVE_SET('',(#3));\n"
    ));
    let im = import(&text, &ImportOptions::default()).expect("reads");
    let id = &im.file.curves[0].id;
    assert_eq!(id, &format!("{} #3", "N".repeat(kerf_step::MAX_NAME_CHARS)));
    assert!(
        im.report
            .skipped
            .iter()
            .any(|s| s.contains("10000 characters")),
        "{:?}",
        im.report.skipped
    );
}

#[test]
fn placements_that_multiply_past_the_budget_are_refused() {
    // Representations #100 .. #104, each placed ten times into the next (10^4 instances of
    // #100), then 30 more placed into #100: 300,000 placements asked for, refused at the
    // budget of 200,000 rather than built (a 300 KB file of this shape took 3.8 GB).
    let mut b =
        String::from("#1=CARTESIAN_POINT('',(0.,0.,0.));\n#2=AXIS2_PLACEMENT_3D('',#1,$,$);\n");
    let mut id = 1000;
    let mut next = || {
        id += 1;
        id
    };
    for r in 100..=104 {
        b.push_str(&format!("#{r}=SHAPE_REPRESENTATION('',(#2),$);\n"));
    }
    let mut place = |b: &mut String, child: u64, parent: u64, k: usize| {
        let (p, a, t, rel) = (next(), next(), next(), next());
        b.push_str(&format!(
            "#{p}=CARTESIAN_POINT('',({k}.,0.,0.));\n#{a}=AXIS2_PLACEMENT_3D('',#{p},$,$);\n\
             #{t}=ITEM_DEFINED_TRANSFORMATION('','',#2,#{a});\n\
             #{rel}=(REPRESENTATION_RELATIONSHIP('','',#{child},#{parent})REPRESENTATION_RELATIONSHIP_WITH_TRANSFORMATION(#{t})SHAPE_REPRESENTATION_RELATIONSHIP());\n"
        ));
    };
    for r in 100..104u64 {
        for k in 0..10 {
            place(&mut b, r, r + 1, k);
        }
    }
    for j in 0..30u64 {
        let r = 200 + j;
        b.push_str(&format!("#{r}=SHAPE_REPRESENTATION('',(#2),$);\n"));
        place(&mut b, r, 100, 1);
    }
    b.push_str("#9=CIRCLE('',#2,5.);\n#10=GEOMETRIC_CURVE_SET('',(#9));\n");
    let text = format!(
        "ISO-10303-21;\nHEADER;\nFILE_SCHEMA(('AUTOMOTIVE_DESIGN'));\nENDSEC;\nDATA;\n{b}ENDSEC;\nEND-ISO-10303-21;\n"
    );
    let e = kerf_step::import(&text, &kerf_step::ImportOptions::default()).expect_err("budget");
    assert!(e.to_string().contains("past 200000 placements"), "{e}");
}
