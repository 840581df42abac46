//! The headless browser the page tests use: Chromium from the distribution's packages
//! (`scripts/setup.sh` installs it).
#![allow(dead_code)] // not every test file needs it

use std::process::Command;

/// The browser, if there is one: `None` to skip (unless `IMPACT_REQUIRE_BROWSER` is set).
pub fn chromium() -> Option<&'static str> {
    for name in ["chromium", "chromium-browser", "google-chrome"] {
        if Command::new(name)
            .arg("--version")
            .output()
            .is_ok_and(|o| o.status.success())
        {
            return Some(name);
        }
    }
    assert!(
        std::env::var_os("IMPACT_REQUIRE_BROWSER").is_none(),
        "no chromium: scripts/setup.sh installs it"
    );
    eprintln!("skipped: no chromium (scripts/setup.sh installs it)");
    None
}
