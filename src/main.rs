fn main() {
    println!("{:?}", psa_esp::provenance::build_info());
}
