//! The ROS 2 messages a calibration run records, decoded from CDR: the
//! fields activecal uses, in the order of their standard definitions.

use super::cdr::Cdr;

/// A decoding failure: the field and what is wrong (the caller adds the
/// bag, topic and message index).
pub type FieldError = (&'static str, String);

type Decoded<T> = std::result::Result<T, FieldError>;

fn at<T>(field: &'static str, r: std::result::Result<T, String>) -> Decoded<T> {
    r.map_err(|m| (field, m))
}

/// `sensor_msgs/msg/JointState`.
pub const JOINT_STATE: &str = "sensor_msgs/msg/JointState";
/// `geometry_msgs/msg/PointStamped`.
pub const POINT_STAMPED: &str = "geometry_msgs/msg/PointStamped";
/// `geometry_msgs/msg/PoseStamped`.
pub const POSE_STAMPED: &str = "geometry_msgs/msg/PoseStamped";
/// `geometry_msgs/msg/TransformStamped`.
pub const TRANSFORM_STAMPED: &str = "geometry_msgs/msg/TransformStamped";
/// `tf2_msgs/msg/TFMessage`.
pub const TF_MESSAGE: &str = "tf2_msgs/msg/TFMessage";
/// `sensor_msgs/msg/CameraInfo`.
pub const CAMERA_INFO: &str = "sensor_msgs/msg/CameraInfo";
/// `sensor_msgs/msg/Image`.
pub const IMAGE: &str = "sensor_msgs/msg/Image";
/// `sensor_msgs/msg/CompressedImage`.
pub const COMPRESSED_IMAGE: &str = "sensor_msgs/msg/CompressedImage";

/// `std_msgs/msg/Header`: the stamp (seconds) and the frame.
#[derive(Clone, Debug, PartialEq)]
pub struct Header {
    /// The stamp in seconds (`sec + nanosec·1e-9`).
    pub stamp: f64,
    /// The frame the data are in.
    pub frame_id: String,
}

fn header(c: &mut Cdr<'_>) -> Decoded<Header> {
    let sec = at("header.stamp.sec", c.i32())?;
    let nanosec = at("header.stamp.nanosec", c.u32())?;
    let frame_id = at("header.frame_id", c.string())?;
    Ok(Header {
        stamp: f64::from(sec) + f64::from(nanosec) * 1e-9,
        frame_id,
    })
}

/// `sensor_msgs/msg/JointState` (velocity and effort are not read).
#[derive(Clone, Debug, PartialEq)]
pub struct JointState {
    /// The header.
    pub header: Header,
    /// The joints' names.
    pub name: Vec<String>,
    /// Their positions (radians, metres).
    pub position: Vec<f64>,
}

/// Decodes a `JointState`.
pub fn joint_state(data: &[u8]) -> Decoded<JointState> {
    let mut c = at("(header)", Cdr::new(data))?;
    let header = header(&mut c)?;
    let name = at("name", c.strings())?;
    let position = at("position", c.f64s())?;
    if position.len() != name.len() {
        return Err((
            "position",
            format!("{} position(s) for {} name(s)", position.len(), name.len()),
        ));
    }
    Ok(JointState {
        header,
        name,
        position,
    })
}

/// A stamped position and, for poses and transforms, orientation (a unit
/// quaternion `[w, x, y, z]`), in the header's frame.
#[derive(Clone, Debug, PartialEq)]
pub struct Stamped {
    /// The header.
    pub header: Header,
    /// The child frame of a transform (empty otherwise).
    pub child_frame_id: String,
    /// The position (metres).
    pub position: [f64; 3],
    /// The orientation `[w, x, y, z]`, if the message has one.
    pub orientation: Option<[f64; 4]>,
}

fn quaternion(c: &mut Cdr<'_>, field: &'static str) -> Decoded<[f64; 4]> {
    let [x, y, z, w] = at(field, c.f64_array::<4>())?;
    Ok([w, x, y, z])
}

/// Decodes a `PointStamped`.
pub fn point_stamped(data: &[u8]) -> Decoded<Stamped> {
    let mut c = at("(header)", Cdr::new(data))?;
    let header = header(&mut c)?;
    let position = at("point", c.f64_array::<3>())?;
    Ok(Stamped {
        header,
        child_frame_id: String::new(),
        position,
        orientation: None,
    })
}

/// Decodes a `PoseStamped`.
pub fn pose_stamped(data: &[u8]) -> Decoded<Stamped> {
    let mut c = at("(header)", Cdr::new(data))?;
    let header = header(&mut c)?;
    let position = at("pose.position", c.f64_array::<3>())?;
    let orientation = Some(quaternion(&mut c, "pose.orientation")?);
    Ok(Stamped {
        header,
        child_frame_id: String::new(),
        position,
        orientation,
    })
}

fn transform_stamped_in(c: &mut Cdr<'_>) -> Decoded<Stamped> {
    let header = header(c)?;
    let child_frame_id = at("child_frame_id", c.string())?;
    let position = at("transform.translation", c.f64_array::<3>())?;
    let orientation = Some(quaternion(c, "transform.rotation")?);
    Ok(Stamped {
        header,
        child_frame_id,
        position,
        orientation,
    })
}

/// Decodes a `TransformStamped`.
pub fn transform_stamped(data: &[u8]) -> Decoded<Stamped> {
    let mut c = at("(header)", Cdr::new(data))?;
    transform_stamped_in(&mut c)
}

/// Decodes a `TFMessage`: its transforms.
pub fn tf_message(data: &[u8]) -> Decoded<Vec<Stamped>> {
    let mut c = at("(header)", Cdr::new(data))?;
    let n = at("transforms", c.sequence_len(4))?;
    (0..n).map(|_| transform_stamped_in(&mut c)).collect()
}

/// `sensor_msgs/msg/CameraInfo`: the image size and the calibration.
#[derive(Clone, Debug, PartialEq)]
pub struct CameraInfo {
    /// The header.
    pub header: Header,
    /// Image height (pixels).
    pub height: u32,
    /// Image width (pixels).
    pub width: u32,
    /// `plumb_bob`, `rational_polynomial`, `equidistant`, …
    pub distortion_model: String,
    /// The distortion coefficients.
    pub d: Vec<f64>,
    /// The camera matrix, row-major.
    pub k: [f64; 9],
}

/// Decodes a `CameraInfo` (the rectification and projection matrices,
/// binning and region of interest are not kept).
pub fn camera_info(data: &[u8]) -> Decoded<CameraInfo> {
    let mut c = at("(header)", Cdr::new(data))?;
    let header = header(&mut c)?;
    let height = at("height", c.u32())?;
    let width = at("width", c.u32())?;
    let distortion_model = at("distortion_model", c.string())?;
    let d = at("d", c.f64s())?;
    let k = at("k", c.f64_array::<9>())?;
    Ok(CameraInfo {
        header,
        height,
        width,
        distortion_model,
        d,
        k,
    })
}

/// The header and size of an `Image` (`width`, `height`, `encoding`; the
/// pixels are skipped) or a `CompressedImage` (`format`; size 0).
#[derive(Clone, Debug, PartialEq)]
pub struct ImageHeader {
    /// The header.
    pub header: Header,
    /// Width (pixels; 0 for a compressed image).
    pub width: u32,
    /// Height (pixels; 0 for a compressed image).
    pub height: u32,
    /// The encoding (`rgb8`, …) or the compressed format (`jpeg`, …).
    pub encoding: String,
    /// Bytes of pixel data.
    pub bytes: usize,
}

/// Decodes an `Image`'s header and size.
pub fn image_header(data: &[u8]) -> Decoded<ImageHeader> {
    image(data).map(ImageData::header_only)
}

/// Decodes a `CompressedImage`'s header and format.
pub fn compressed_image_header(data: &[u8]) -> Decoded<ImageHeader> {
    compressed_image(data).map(ImageData::header_only)
}

/// An `Image` or a `CompressedImage`: its header, size and bytes, as
/// stored (decoded into grey levels by
/// [`crate::io::images::decode::decode_message`]).
#[derive(Clone, Debug, PartialEq)]
pub struct ImageData<'a> {
    /// The header.
    pub header: Header,
    /// Width (pixels; 0 for a compressed image).
    pub width: u32,
    /// Height (pixels; 0 for a compressed image).
    pub height: u32,
    /// The encoding (`mono8`, `rgb8`, …) or the compressed format
    /// (`png`, `jpeg`, `rgb8; png compressed bgr8`, …).
    pub encoding: String,
    /// Bytes per row (0 for a compressed image).
    pub step: u32,
    /// Whether the image was compressed (`CompressedImage`).
    pub compressed: bool,
    /// The pixels, or the compressed file's bytes.
    pub data: &'a [u8],
}

impl ImageData<'_> {
    /// The header, size and encoding, with the count of bytes for the
    /// bytes.
    fn header_only(self) -> ImageHeader {
        ImageHeader {
            header: self.header,
            width: self.width,
            height: self.height,
            encoding: self.encoding,
            bytes: self.data.len(),
        }
    }
}

/// Decodes an `Image` with its pixels.
pub fn image(data: &[u8]) -> Decoded<ImageData<'_>> {
    let mut c = at("(header)", Cdr::new(data))?;
    let header = header(&mut c)?;
    let height = at("height", c.u32())?;
    let width = at("width", c.u32())?;
    let encoding = at("encoding", c.string())?;
    let _big_endian = at("is_bigendian", c.u8())?;
    let step = at("step", c.u32())?;
    let data = at("data", c.bytes())?;
    Ok(ImageData {
        header,
        width,
        height,
        encoding,
        step,
        compressed: false,
        data,
    })
}

/// Decodes a `CompressedImage` with its bytes.
pub fn compressed_image(data: &[u8]) -> Decoded<ImageData<'_>> {
    let mut c = at("(header)", Cdr::new(data))?;
    let header = header(&mut c)?;
    let encoding = at("format", c.string())?;
    let data = at("data", c.bytes())?;
    Ok(ImageData {
        header,
        width: 0,
        height: 0,
        encoding,
        step: 0,
        compressed: true,
        data,
    })
}
