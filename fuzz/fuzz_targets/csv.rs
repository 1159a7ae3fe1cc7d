//! The line-numbered CSV reader of `reflectance` and `color`: never panics, and a table
//! it accepts has one field per column in every row.
#![no_main]
use bubbles_fuzz::csv_table::CsvTable;
use libfuzzer_sys::fuzz_target;

fuzz_target!(|text: &str| {
    if let Ok(table) = CsvTable::parse(text, &["thickness_nm", "angle_deg"], &["n_film"]) {
        for row in table.rows() {
            let d = row.number("thickness_nm");
            let n = row.number_or("n_film", 1.33);
            if let (Ok(d), Ok(n)) = (d, n) {
                assert!(!d.is_nan() && !n.is_nan(), "NaN accepted from {text:?}");
            }
        }
    }
});
