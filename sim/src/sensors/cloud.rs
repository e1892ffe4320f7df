//! Point clouds, kept in sensor_msgs/PointCloud2's layout (little-endian, one `point_step` of
//! bytes per point, rows of `width` points): a 3D lidar's x y z intensity ring (the fields
//! velodyne_pointcloud and velodyne_simulator use) and a depth camera's organized x y z rgb in
//! its optical frame (gazebo_ros_openni_kinect's). Both ROS wires and MCAP send the bytes as
//! they are; the recorder reads the points back with [`PointCloud::xyz`].

use crate::model::camera_info::CameraInfo;

/// `sensor_msgs/PointField`'s `UINT16`.
pub const POINT_FIELD_UINT16: u8 = 4;
/// `sensor_msgs/PointField`'s `FLOAT32`.
pub const POINT_FIELD_FLOAT32: u8 = 7;

/// One field of every point, as `sensor_msgs/PointField` describes it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct CloudField {
    /// Its name (`x`, `ring`, ...).
    pub name: &'static str,
    /// Where it starts in the point (bytes).
    pub offset_bytes: u32,
    /// `sensor_msgs/PointField`'s datatype constant.
    pub datatype: u8,
    /// How many values (1).
    pub count: u32,
}

const fn field(name: &'static str, offset_bytes: u32, datatype: u8) -> CloudField {
    CloudField {
        name,
        offset_bytes,
        datatype,
        count: 1,
    }
}

/// What a point holds.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum CloudLayout {
    /// x y z (float32 at 0, 4, 8), intensity (float32 at 16), ring (uint16 at 20); 32 bytes,
    /// PCL's aligned `PointXYZIR` as velodyne_pointcloud publishes it.
    XyzIntensityRing,
    /// x y z (float32 at 0, 4, 8), rgb (at 16: the bytes b g r 0, PCL's packed colour read as a
    /// float32); 32 bytes, PCL's `PointXYZRGB`.
    XyzRgb,
}

const XYZIR: [CloudField; 5] = [
    field("x", 0, POINT_FIELD_FLOAT32),
    field("y", 4, POINT_FIELD_FLOAT32),
    field("z", 8, POINT_FIELD_FLOAT32),
    field("intensity", 16, POINT_FIELD_FLOAT32),
    field("ring", 20, POINT_FIELD_UINT16),
];

const XYZRGB: [CloudField; 4] = [
    field("x", 0, POINT_FIELD_FLOAT32),
    field("y", 4, POINT_FIELD_FLOAT32),
    field("z", 8, POINT_FIELD_FLOAT32),
    field("rgb", 16, POINT_FIELD_FLOAT32),
];

impl CloudLayout {
    /// The fields, in offset order.
    pub fn fields(self) -> &'static [CloudField] {
        match self {
            Self::XyzIntensityRing => &XYZIR,
            Self::XyzRgb => &XYZRGB,
        }
    }

    /// Bytes per point.
    pub fn point_step_bytes(self) -> u32 {
        32
    }
}

/// Which sensor a cloud comes from.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum CloudSource {
    /// The robot's 3D lidar number `n` (`RobotModel::lidars` order).
    Lidar(usize),
    /// The depth camera.
    DepthCamera,
}

/// One point cloud, shaped like `sensor_msgs/PointCloud2`.
#[derive(Debug, Clone, PartialEq)]
pub struct PointCloud {
    /// Which sensor took it.
    pub source: CloudSource,
    /// Sim time it was taken (s).
    pub stamp_s: f64,
    /// Cloud number since the start (0, 1, ...).
    pub seq: u64,
    /// The frame its points are in.
    pub frame_id: String,
    /// Rows (1 for an unorganized cloud).
    pub height: u32,
    /// Points per row.
    pub width: u32,
    /// What each point holds.
    pub layout: CloudLayout,
    /// The points, `layout.point_step_bytes()` each, little-endian.
    pub data: Vec<u8>,
    /// No point is NaN.
    pub is_dense: bool,
}

impl PointCloud {
    /// An empty cloud from `source` in `frame_id`.
    pub fn new(source: CloudSource, frame_id: &str, layout: CloudLayout) -> Self {
        Self {
            source,
            stamp_s: 0.0,
            seq: 0,
            frame_id: frame_id.to_owned(),
            height: 1,
            width: 0,
            layout,
            data: Vec::new(),
            is_dense: true,
        }
    }

    /// Bytes per point.
    pub fn point_step_bytes(&self) -> u32 {
        self.layout.point_step_bytes()
    }

    /// Bytes per row.
    pub fn row_step_bytes(&self) -> u32 {
        self.width * self.point_step_bytes()
    }

    /// Points, NaN ones included.
    pub fn len(&self) -> usize {
        self.data.len() / self.point_step_bytes() as usize
    }

    /// True when it holds no point.
    pub fn is_empty(&self) -> bool {
        self.data.is_empty()
    }

    fn f32_at(&self, point: usize, offset: usize) -> f32 {
        let at = point * self.point_step_bytes() as usize + offset;
        self.data
            .get(at..at + 4)
            .and_then(|b| b.try_into().ok())
            .map_or(f32::NAN, f32::from_le_bytes)
    }

    /// Point `i`'s x y z (m, in `frame_id`; NaN where the sensor saw nothing).
    pub fn xyz(&self, i: usize) -> [f32; 3] {
        [self.f32_at(i, 0), self.f32_at(i, 4), self.f32_at(i, 8)]
    }

    /// How many points are not NaN (no scan for a dense cloud).
    pub fn valid_len(&self) -> usize {
        if self.is_dense {
            self.len()
        } else {
            self.points().count()
        }
    }

    /// The points that are not NaN, with their index.
    pub fn points(&self) -> impl Iterator<Item = (usize, [f32; 3])> + '_ {
        (0..self.len())
            .map(|i| (i, self.xyz(i)))
            .filter(|(_, p)| p.iter().all(|v| v.is_finite()))
    }

    /// Point `i`'s ring (a lidar's beam, 0 the lowest), for [`CloudLayout::XyzIntensityRing`].
    pub fn ring(&self, i: usize) -> Option<u16> {
        let at = i * self.point_step_bytes() as usize + 20;
        (self.layout == CloudLayout::XyzIntensityRing)
            .then(|| self.data.get(at..at + 2))
            .flatten()
            .map(|b| u16::from_le_bytes([b[0], b[1]]))
    }

    /// Point `i`'s colour (r, g, b), for [`CloudLayout::XyzRgb`].
    pub fn rgb(&self, i: usize) -> Option<[u8; 3]> {
        let at = i * self.point_step_bytes() as usize + 16;
        (self.layout == CloudLayout::XyzRgb)
            .then(|| self.data.get(at..at + 3))
            .flatten()
            .map(|b| [b[2], b[1], b[0]])
    }

    /// Appends a lidar point.
    pub(crate) fn push_lidar_point(&mut self, xyz: [f32; 3], intensity: f32, ring: u16) {
        let at = self.data.len();
        self.data.resize(at + 32, 0);
        write_lidar_point(&mut self.data[at..], xyz, intensity, ring);
    }
}

/// One lidar point into its 32 bytes `p`: x y z, intensity, ring (padding left as it is).
pub(crate) fn write_lidar_point(p: &mut [u8], xyz: [f32; 3], intensity: f32, ring: u16) {
    for (k, v) in xyz.iter().enumerate() {
        p[4 * k..4 * k + 4].copy_from_slice(&v.to_le_bytes());
    }
    p[16..20].copy_from_slice(&intensity.to_le_bytes());
    p[20..22].copy_from_slice(&ring.to_le_bytes());
}

/// Builds a depth camera's organized cloud from its depth and colour images, with the per
/// column and per row factors worked out once.
#[derive(Debug, Clone, Default)]
pub struct DepthCloudBuilder {
    /// `(u - cx) / fx` per column.
    x_per_depth: Vec<f32>,
    /// `(v - cy) / fy` per row.
    y_per_depth: Vec<f32>,
}

impl DepthCloudBuilder {
    /// The builder for images calibrated as `info` (rover's pinhole: pixel centres at integer
    /// coordinates, as its depth image is rendered).
    pub fn new(info: &CameraInfo) -> Self {
        let (fx, fy) = (info.k[0], info.k[4]);
        let (cx, cy) = info.principal_point();
        Self {
            x_per_depth: (0..info.width)
                .map(|u| ((f64::from(u) - cx) / fx) as f32)
                .collect(),
            y_per_depth: (0..info.height)
                .map(|v| ((f64::from(v) - cy) / fy) as f32)
                .collect(),
        }
    }

    /// Fills `cloud` (its data buffer reused) from a depth image (m along the optical axis, NaN
    /// where nothing is in range) and its `rgb8` image: one point per pixel, NaN where the
    /// depth is not within (`cutoff_m`, `cutoff_max_m`), as gazebo_ros_openni_kinect does.
    /// Images of another size than the calibration's leave the cloud empty.
    pub fn fill(
        &self,
        depth_m: &[f32],
        rgb: &[u8],
        (cutoff_m, cutoff_max_m): (f64, f64),
        cloud: &mut PointCloud,
    ) {
        let (w, h) = (self.x_per_depth.len(), self.y_per_depth.len());
        cloud.layout = CloudLayout::XyzRgb;
        cloud.is_dense = true;
        if depth_m.len() != w * h || rgb.len() != w * h * 3 {
            cloud.data.clear();
            cloud.width = 0;
            cloud.height = 1;
            return;
        }
        cloud.width = w as u32;
        cloud.height = h as u32;
        if cloud.data.len() != w * h * 32 {
            // Padding bytes stay zero from here on: every fill writes the same bytes.
            cloud.data.clear();
            cloud.data.resize(w * h * 32, 0);
        }
        let (lo, hi) = (cutoff_m as f32, cutoff_max_m as f32);
        let nan = f32::NAN.to_le_bytes();
        for (v, &y_per) in self.y_per_depth.iter().enumerate() {
            let row = v * w;
            for (u, &x_per) in self.x_per_depth.iter().enumerate() {
                let i = row + u;
                let z = depth_m[i];
                let p = &mut cloud.data[i * 32..i * 32 + 32];
                if z > lo && z < hi {
                    p[0..4].copy_from_slice(&(z * x_per).to_le_bytes());
                    p[4..8].copy_from_slice(&(z * y_per).to_le_bytes());
                    p[8..12].copy_from_slice(&z.to_le_bytes());
                } else {
                    p[0..4].copy_from_slice(&nan);
                    p[4..8].copy_from_slice(&nan);
                    p[8..12].copy_from_slice(&nan);
                    cloud.is_dense = false;
                }
                p[16] = rgb[3 * i + 2];
                p[17] = rgb[3 * i + 1];
                p[18] = rgb[3 * i];
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_lidar_point_reads_back() {
        let mut c = PointCloud::new(
            CloudSource::Lidar(0),
            "velodyne",
            CloudLayout::XyzIntensityRing,
        );
        c.push_lidar_point([1.0, -2.0, 0.5], 0.0, 7);
        c.width = 1;
        assert_eq!(c.len(), 1);
        assert_eq!(c.xyz(0), [1.0, -2.0, 0.5]);
        assert_eq!(c.ring(0), Some(7));
        assert_eq!(c.rgb(0), None);
        assert_eq!(c.row_step_bytes(), 32);
    }
}
