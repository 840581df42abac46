//! What an IDE recording says of itself besides its samples: the recorder (`RecorderInfo`:
//! product, part number, serial, revisions, date of manufacture), its sensors (`SensorList`:
//! name, serial) and the factory calibration (`CalibrationList`'s date, expiry and serial),
//! element IDs from idelib's schemata/mide_ide.xml. A report's title block shows them.
//!
//! None of it enters a sample's value: an element here that cannot be decoded (a number of
//! more than 8 bytes, a sensor entry running past its list) is left out, never the reason a
//! recording is refused.

use super::ebml;

// RecorderInfo's children.
const RECORDER_SERIAL: u32 = 0x5212;
const PRODUCT_NAME: u32 = 0x5214;
const USER_DEVICE_NAME: u32 = 0x5215;
const HW_REV: u32 = 0x5216;
const FW_REV: u32 = 0x5217;
const PART_NUMBER: u32 = 0x5218;
const DATE_OF_MANUFACTURE: u32 = 0x5219;
const FW_REV_STR: u32 = 0x521C;
// SensorList's.
const SENSOR: u32 = 0x5241;
const SENSOR_ID: u32 = 0x5242;
const SENSOR_NAME: u32 = 0x5243;
const TRACEABILITY: u32 = 0x5250;
const SENSOR_SERIAL: u32 = 0x5251;
// CalibrationList's own (beside its polynomials).
pub(super) const CALIBRATION_DATE: u32 = 0x4B20;
pub(super) const CALIBRATION_SERIAL: u32 = 0x4B21;
pub(super) const CALIBRATION_EXPIRY: u32 = 0x4B22;

/// The recorder, as its `RecorderInfo` names it (empty texts and `None`: not recorded).
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct Recorder {
    /// `Slam Stick X (2000g+DC)`.
    pub product_name: String,
    /// `LOG-0002-02kG-DC`.
    pub part_number: String,
    pub serial: Option<u64>,
    /// The name a user gave the recorder.
    pub user_name: String,
    pub hardware_revision: Option<u64>,
    /// The firmware's revision string (`1.20.1`), else its revision number.
    pub firmware: String,
    /// Date of manufacture, Unix seconds (UTC).
    pub manufactured_unix_s: Option<u64>,
}

/// A sensor of the recorder (`SensorList`): `832M1 PE Accelerometer`, serial `5663-033`.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct Sensor {
    pub id: u64,
    pub name: String,
    /// The sensor maker's serial number (`TraceabilityData`).
    pub serial: Option<String>,
}

/// The factory calibration the file's polynomials come from.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Calibration {
    /// Its date and the date it expires, Unix seconds (UTC).
    pub date_unix_s: Option<u64>,
    pub expiry_unix_s: Option<u64>,
    /// The maker's number of this calibration.
    pub serial: Option<u64>,
}

impl Calibration {
    /// Reads one of `CalibrationList`'s own children (`id`); false if it is none of them.
    pub(super) fn read(&mut self, id: u32, body: &[u8], at: u64) -> bool {
        let field = match id {
            CALIBRATION_DATE => &mut self.date_unix_s,
            CALIBRATION_EXPIRY => &mut self.expiry_unix_s,
            CALIBRATION_SERIAL => &mut self.serial,
            _ => return false,
        };
        *field = ebml::uint(body, at).ok();
        true
    }
}

impl Recorder {
    /// Reads a child of `RecorderInfo`.
    pub(super) fn read(&mut self, id: u32, body: &[u8], at: u64) {
        let uint = || ebml::uint(body, at).ok();
        match id {
            RECORDER_SERIAL => self.serial = uint(),
            PRODUCT_NAME => self.product_name = ebml::string(body),
            USER_DEVICE_NAME => self.user_name = ebml::string(body),
            HW_REV => self.hardware_revision = uint(),
            FW_REV if self.firmware.is_empty() => {
                self.firmware = uint().map_or_else(String::new, |v| v.to_string());
            }
            FW_REV_STR => self.firmware = ebml::string(body),
            PART_NUMBER => self.part_number = ebml::string(body),
            DATE_OF_MANUFACTURE => self.manufactured_unix_s = uint(),
            _ => {}
        }
    }
}

/// The sensors of a `SensorList` element's body (those read before an element that cannot
/// be; a sensor without a readable id is left out).
pub(super) fn sensors(body: &[u8], base: u64) -> Vec<Sensor> {
    let mut out = Vec::new();
    for (id, b, at) in ebml::children(body, base).map_while(Result::ok) {
        if id != SENSOR {
            continue;
        }
        let (mut s, mut sensor_id) = (Sensor::default(), None);
        for (cid, v, o) in ebml::children(b, at).map_while(Result::ok) {
            match cid {
                SENSOR_ID => sensor_id = ebml::uint(v, o).ok(),
                SENSOR_NAME => s.name = ebml::string(v),
                TRACEABILITY => {
                    for (tid, tv, _) in ebml::children(v, o).map_while(Result::ok) {
                        if tid == SENSOR_SERIAL {
                            s.serial = Some(ebml::string(tv)).filter(|x| !x.is_empty());
                        }
                    }
                }
                _ => {}
            }
        }
        let Some(id) = sensor_id else { continue };
        s.id = id;
        out.retain(|o: &Sensor| o.id != s.id);
        out.push(s);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::super::IdeFile;

    /// The bundled enDAQ recording's own account of its recorder, sensors and calibration
    /// (as `idelib` reads them: `doc.recorderInfo`, `doc.sensors`, `doc.transforms`).
    #[test]
    fn the_bundled_recording_names_its_recorder_sensors_and_calibration() {
        let path = concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/../data/endaq-high-drop/High-Drop.IDE"
        );
        let f = IdeFile::open(path).unwrap();
        let info = f.info();
        let r = &info.recorder;
        assert_eq!(r.product_name, "Slam Stick X (2000g+DC)");
        assert_eq!(r.part_number, "LOG-0002-02kG-DC");
        assert_eq!(r.serial, Some(6468));
        assert_eq!(r.firmware, "1.20.1");
        assert_eq!(r.hardware_revision, Some(12));
        assert_eq!(r.manufactured_unix_s, Some(0x5C4B_B701));
        assert_eq!(info.calibration.date_unix_s, Some(0x5C4F_979F));
        assert_eq!(info.calibration.serial, Some(4953));
        assert_eq!(info.calibration.expiry_unix_s, None);
        let names: Vec<&str> = info.sensors.iter().map(|s| s.name.as_str()).collect();
        assert_eq!(names[0], "832M1 PE Accelerometer");
        assert_eq!(info.sensors[0].serial.as_deref(), Some("5663-033"));
        assert_eq!(names[1], "ADXL345 Low-G DC Accelerometer");
        assert_eq!(info.sensors[1].serial, None);
        // Each subchannel names its sensor: the 2000 g channel the piezo-electric one.
        assert_eq!(f.sensor_of(8, 1).map(|s| s.name.as_str()), Some(names[0]));
        assert_eq!(f.sensor_of(32, 2).map(|s| s.name.as_str()), Some(names[1]));
        assert_eq!(f.sensor_of(8, 9), None);
    }
}
