use hdi_tribology::surface::special::*;
#[test]
fn scratch() {
    for x in [24.9f64, 25.0, 25.0 + 1e-12, 25.1] {
        println!("{x} {:.17e}", bessel_i0e(x));
    }
}
