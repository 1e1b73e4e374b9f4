//! Input validation of the peak laws and the serde scene description.

use hdi_tribology::surface::{
    Discrete, Empirical, Gaussian, GaussianHeights, PeakDistribution, PeakModel, RiceMaxima, Rician,
};
use hdi_tribology::{Error, Result};

fn field<T: std::fmt::Debug>(r: Result<T>) -> String {
    match r {
        Err(Error::InvalidInput { field, .. }) => field,
        other => panic!("expected InvalidInput, got {other:?}"),
    }
}

#[test]
fn constructors_name_the_bad_field() {
    assert_eq!(field(Gaussian::new(f64::NAN, 1.0)), "peaks.mean");
    assert_eq!(field(Gaussian::new(0.0, 0.0)), "peaks.std");
    assert_eq!(field(Gaussian::new(0.0, f64::INFINITY)), "peaks.std");
    assert_eq!(field(RiceMaxima::new(-1.0, 0.5)), "peaks.sigma");
    assert_eq!(field(RiceMaxima::new(1.0, 0.0)), "peaks.epsilon");
    assert_eq!(field(RiceMaxima::new(1.0, 1.0 + 1e-12)), "peaks.epsilon");
    assert_eq!(field(RiceMaxima::new(1.0, f64::NAN)), "peaks.epsilon");
    assert_eq!(field(Rician::new(-1e-9, 1e-9)), "peaks.nu");
    assert_eq!(field(Rician::new(1e-9, 0.0)), "peaks.s");
    assert_eq!(field(GaussianHeights::new(-1e-9)), "surface.sigma");
    assert_eq!(field(GaussianHeights::new(f64::NAN)), "surface.sigma");
}

#[test]
fn histograms_reject_bad_input() {
    let e = |edges: &[f64], counts: &[f64]| field(Empirical::from_histogram(edges, counts));
    assert_eq!(e(&[0.0], &[]), "peaks.counts"); // empty
    assert_eq!(e(&[0.0, 1.0, 2.0], &[1.0]), "peaks.edges"); // length mismatch
    assert_eq!(e(&[0.0, 2.0, 1.0], &[1.0, 1.0]), "peaks.edges"); // unsorted
    assert_eq!(e(&[0.0, 1.0, 1.0], &[1.0, 1.0]), "peaks.edges"); // repeated edge
    assert_eq!(e(&[0.0, f64::INFINITY], &[1.0]), "peaks.edges");
    assert_eq!(e(&[0.0, 1.0], &[-1.0]), "peaks.counts");
    assert_eq!(e(&[0.0, 1.0], &[f64::NAN]), "peaks.counts");
    assert_eq!(e(&[0.0, 1.0, 2.0], &[0.0, 0.0]), "peaks.counts"); // zero total
    let big = vec![1.0; 10_000_001];
    let edges: Vec<f64> = (0..=big.len()).map(|i| i as f64).collect();
    assert_eq!(e(&edges, &big), "peaks.counts"); // oversized
                                                 // Zero-count bins inside are fine.
    assert!(Empirical::from_histogram(&[0.0, 1.0, 2.0, 3.0], &[1.0, 0.0, 1.0]).is_ok());
}

#[test]
fn samples_reject_bad_input() {
    let s = |v: &[f64]| field(Empirical::from_sample(v));
    assert_eq!(s(&[]), "peaks.sample");
    assert_eq!(s(&[1.0]), "peaks.sample");
    assert_eq!(s(&[1.0, f64::NAN]), "peaks.sample");
    assert_eq!(s(&[2.0, 2.0, 2.0]), "peaks.sample"); // no spread
    assert_eq!(s(&vec![0.0; 10_000_001]), "peaks.sample");
    // Two values: one or more bins, normalised.
    let e = Empirical::from_sample(&[0.0, 1.0]).unwrap();
    assert!((e.weights().iter().sum::<f64>() - 1.0).abs() < 1e-15);
}

#[test]
fn discrete_rejects_bad_input() {
    assert_eq!(field(Discrete::from_heights(vec![])), "peaks.heights");
    assert_eq!(
        field(Discrete::from_heights(vec![1.0, f64::INFINITY])),
        "peaks.heights"
    );
    let g = Gaussian::new(0.0, 1.0).unwrap();
    assert_eq!(field(Discrete::sample(&g, 0, 1)), "peaks.n");
    assert_eq!(field(Discrete::sample(&g, 10_000_001, 1)), "peaks.n");
}

#[test]
fn peak_model_builds_every_family() {
    let models = vec![
        PeakModel::Gaussian {
            mean_m: 1e-9,
            std_m: 1e-9,
        },
        PeakModel::RiceMaxima {
            sigma_m: 1e-9,
            epsilon: 0.5,
        },
        PeakModel::Rician {
            nu_m: 1e-9,
            s_m: 1e-9,
        },
        PeakModel::Histogram {
            edges_m: vec![0.0, 1e-9, 2e-9],
            counts: vec![1.0, 2.0],
        },
        PeakModel::Sample {
            heights_m: vec![0.0, 1e-9, 3e-9, 2e-9],
        },
        PeakModel::Discrete {
            heights_m: vec![1e-9, 2e-9],
        },
        PeakModel::DiscreteSampled {
            from: Box::new(PeakModel::Gaussian {
                mean_m: 0.0,
                std_m: 1e-9,
            }),
            n: 50,
            seed: 3,
        },
    ];
    for m in models {
        let law = m.build().unwrap();
        assert!((law.partial_moment(-1.0, 0.0) - 1.0).abs() < 1e-12, "{m:?}");
        // Round trips through JSON and TOML.
        let json = serde_json::to_string(&m).unwrap();
        assert_eq!(serde_json::from_str::<PeakModel>(&json).unwrap(), m);
        let toml_text = toml::to_string(&m).unwrap();
        assert_eq!(
            toml::from_str::<PeakModel>(&toml_text).unwrap(),
            m,
            "{toml_text}"
        );
    }
}

#[test]
fn peak_model_names_fields_and_rejects_unknown_ones() {
    let bad = [
        (
            PeakModel::Gaussian {
                mean_m: 0.0,
                std_m: -1.0,
            },
            "peaks.std_m",
        ),
        (
            PeakModel::Gaussian {
                mean_m: f64::NAN,
                std_m: 1.0,
            },
            "peaks.mean_m",
        ),
        (
            PeakModel::RiceMaxima {
                sigma_m: 1e-9,
                epsilon: 2.0,
            },
            "peaks.epsilon",
        ),
        (
            PeakModel::RiceMaxima {
                sigma_m: 0.0,
                epsilon: 0.5,
            },
            "peaks.sigma_m",
        ),
        (
            PeakModel::Rician {
                nu_m: -1.0,
                s_m: 1.0,
            },
            "peaks.nu_m",
        ),
        (
            PeakModel::Rician {
                nu_m: 1.0,
                s_m: 0.0,
            },
            "peaks.s_m",
        ),
        (
            PeakModel::Histogram {
                edges_m: vec![1.0, 0.0],
                counts: vec![1.0],
            },
            "peaks.edges_m",
        ),
        (
            PeakModel::Histogram {
                edges_m: vec![0.0, 1.0],
                counts: vec![0.0],
            },
            "peaks.counts",
        ),
        (PeakModel::Sample { heights_m: vec![] }, "peaks.heights_m"),
        (PeakModel::Discrete { heights_m: vec![] }, "peaks.heights_m"),
        (
            PeakModel::DiscreteSampled {
                from: Box::new(PeakModel::Gaussian {
                    mean_m: 0.0,
                    std_m: 1e-9,
                }),
                n: 0,
                seed: 1,
            },
            "peaks.n",
        ),
        (
            PeakModel::DiscreteSampled {
                from: Box::new(PeakModel::Rician {
                    nu_m: 0.0,
                    s_m: -1.0,
                }),
                n: 5,
                seed: 1,
            },
            "peaks.from.s_m",
        ),
    ];
    for (m, want) in bad {
        assert_eq!(field(m.build()), want, "{m:?}");
    }
    let unknown = r#"{"family": "gaussian", "mean_m": 0.0, "std_m": 1e-9, "sdt_m": 1}"#;
    let err = serde_json::from_str::<PeakModel>(unknown)
        .unwrap_err()
        .to_string();
    assert!(err.contains("sdt_m"), "{err}");
    let family = r#"{"family": "weibull", "k": 1.0}"#;
    assert!(serde_json::from_str::<PeakModel>(family).is_err());
    let nested = "family = \"discrete_sampled\"\nn = 10\nseed = 4\n[from]\nfamily = \"rice_maxima\"\nsigma_m = 1e-9\nepsilon = 0.3\n";
    let m: PeakModel = toml::from_str(nested).unwrap();
    assert_eq!(m.build().unwrap().atoms().map(<[f64]>::len), Some(10));
}

#[test]
fn partial_moments_are_finite_for_extreme_arguments() {
    let laws: Vec<Box<dyn PeakDistribution>> = vec![
        Box::new(Gaussian::new(0.0, 1e-9).unwrap()),
        Box::new(RiceMaxima::new(1e-9, 0.3).unwrap()),
        Box::new(Rician::new(1e-9, 1e-9).unwrap()),
        Box::new(Empirical::from_histogram(&[0.0, 1e-9], &[1.0]).unwrap()),
        Box::new(Discrete::from_heights(vec![0.0, 1e-9]).unwrap()),
    ];
    for law in &laws {
        for d in [
            -1e3,
            -1.0,
            -1e-6,
            0.0,
            1e-6,
            1.0,
            1e3,
            f64::MAX / 4.0,
            -f64::MAX / 4.0,
        ] {
            for p in [0.0, 0.5, 1.5, 3.0] {
                let m = law.partial_moment(d, p);
                // Far below the support M_p ≈ |d|^p may overflow only for p·log|d| > 308.
                if d.abs() < 1e100 {
                    assert!(m.is_finite() && m >= 0.0, "{law:?} d={d} p={p}: {m}");
                } else {
                    assert!(m >= 0.0 || m.is_infinite(), "{law:?} d={d} p={p}: {m}");
                }
            }
        }
    }
}
