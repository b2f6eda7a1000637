//! `cargo run --release -p nscdd-fuzz --example replay -- TARGET FILE`: runs one
//! saved input with the default panic report (message and place).
fn main() {
    let a: Vec<String> = std::env::args().collect();
    let data = std::fs::read(&a[2]).expect("the input file");
    let target = nscdd_fuzz::targets().into_iter().find(|t| t.0 == a[1]).expect("a target name").1;
    target(&data);
    println!("no panic");
}
