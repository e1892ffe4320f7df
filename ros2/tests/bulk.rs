//! rover_ros2::bulk and rover_ros2::acked against a real RTPS reader: a RustDDS participant
//! subscribing best effort reassembles what the bulk writer sends from its own socket — a
//! 640x480 rgb8 image in fragments and a small image in one DATA — byte for byte, in order;
//! one subscribing reliable gets every image the acked writer writes, whole, in order.

use std::time::{Duration, Instant};

use anyhow::{Result, ensure};
use rover_ros2::acked::AckedWriter;
use rover_ros2::bulk::{BulkWriter, FRAGMENT_BYTES};
use rover_ros2::dds::{dds_topic, latched_qos, sensor_qos, writer};
use rover_ros2::msgs::{Header, Image, Lent, RosMessage, Time};
use rustdds::no_key::DataReader;
use rustdds::{CDRDeserializerAdapter, DomainParticipant, TopicKind};
use serde::Deserialize;

/// sensor_msgs/msg/Image as a reader decodes it.
#[derive(Debug, Deserialize)]
struct ReadImage {
    header: Header,
    height: u32,
    width: u32,
    encoding: String,
    is_bigendian: u8,
    step: u32,
    data: Vec<u8>,
}

fn image(seconds: i32, (width, height): (u32, u32)) -> Image {
    let data: Vec<u8> = (0..width * height * 3)
        .map(|k| (k.wrapping_mul(31) ^ (k >> 7)) as u8 ^ seconds as u8)
        .collect();
    Image {
        header: Header {
            stamp: Time {
                sec: seconds,
                nanosec: 250,
            },
            frame_id: "camera_link_optical".into(),
        },
        height,
        width,
        encoding: "rgb8".into(),
        is_bigendian: 0,
        step: width * 3,
        data: Lent::new(data),
    }
}

fn same(read: &ReadImage, sent: &Image) -> bool {
    read.header == sent.header
        && (read.height, read.width, read.step, read.is_bigendian)
            == (sent.height, sent.width, sent.step, sent.is_bigendian)
        && read.encoding == sent.encoding
        && read.data == *sent.data.as_slice()
}

/// A reader of images on `ros_name` with `qos`, on a participant of its own in `domain`
/// (returned with it: the reader lives as long as its participant).
fn image_reader(
    domain: u16,
    ros_name: &str,
    qos: &rustdds::QosPolicies,
) -> Result<(DomainParticipant, ImageReader)> {
    let receiving = DomainParticipant::new(domain)?;
    let topic = receiving.create_topic(
        dds_topic(ros_name),
        Image::DDS_TYPE.to_owned(),
        qos,
        TopicKind::NoKey,
    )?;
    let subscriber = receiving.create_subscriber(qos)?;
    let reader = subscriber.create_datareader_no_key(&topic, Some(qos.clone()))?;
    Ok((receiving, reader))
}

/// A RustDDS reader of [`ReadImage`]s.
type ImageReader = DataReader<ReadImage, CDRDeserializerAdapter<ReadImage>>;

#[test]
fn a_rustdds_reader_reassembles_the_bulk_writers_images() -> Result<()> {
    let domain = 100 + (std::process::id() % 100) as u16;
    let ros_name = "/camera/image_raw";
    let qos = sensor_qos();

    let sending = DomainParticipant::new(domain)?;
    let publisher = sending.create_publisher(&qos)?;
    let w = writer::<Image>(&sending, &publisher, ros_name, &qos)?;
    let mut bulk = BulkWriter::new(&sending, w, ros_name)?;

    let (_receiving, mut reader) = image_reader(domain, ros_name, &qos)?;

    // Discovery: the writer must know the reader and its UDP address.
    let deadline = Instant::now() + Duration::from_secs(20);
    let small = image(1, (8, 4));
    while bulk.matched() != (1, 1) {
        ensure!(
            Instant::now() < deadline,
            "no reader matched: {:?}",
            bulk.matched()
        );
        bulk.write(&small)?;
        std::thread::sleep(Duration::from_millis(100));
    }

    let large = image(2, (640, 480));
    ensure!(large.data.as_slice().len() > 50 * FRAGMENT_BYTES);
    // Best effort may lose a sample: each is written until it is read (a bound, not a timing).
    for sent in [&large, &small, &image(3, (640, 480))] {
        let deadline = Instant::now() + Duration::from_secs(20);
        'sample: loop {
            ensure!(
                Instant::now() < deadline,
                "{}x{} never arrived",
                sent.width,
                sent.height
            );
            bulk.write(sent)?;
            std::thread::sleep(Duration::from_millis(200));
            while let Ok(Some(sample)) = reader.take_next_sample() {
                let read = sample.value();
                if same(read, sent) {
                    break 'sample;
                }
                ensure!(
                    read.header.stamp.sec <= sent.header.stamp.sec,
                    "an image from the future: {:?}",
                    read.header
                );
            }
        }
    }
    Ok(())
}

#[test]
fn a_reliable_rustdds_reader_gets_each_image_of_the_acked_writer_whole() -> Result<()> {
    let domain = 100 + ((std::process::id() + 50) % 100) as u16;
    let ros_name = "/darknet_ros/detection_image";
    let qos = latched_qos();

    let sending = DomainParticipant::new(domain)?;
    let publisher = sending.create_publisher(&qos)?;
    let w = writer::<Image>(&sending, &publisher, ros_name, &qos)?;
    let acked = AckedWriter::new(&sending, w, ros_name)?;

    let (_receiving, mut reader) = image_reader(domain, ros_name, &qos)?;

    // Each image is written once, after the last was read: reliable delivery, no retries.
    for seconds in 1..=4 {
        let sent = image(seconds, (640, 480));
        acked.write(sent.clone());
        let deadline = Instant::now() + Duration::from_secs(30);
        let sample = loop {
            ensure!(Instant::now() < deadline, "image {seconds} never arrived");
            std::thread::sleep(Duration::from_millis(50));
            if let Ok(Some(sample)) = reader.take_next_sample() {
                break sample;
            }
        };
        let read = sample.value();
        ensure!(
            read.header.stamp.sec == seconds,
            "image {} read while waiting for {seconds}",
            read.header.stamp.sec
        );
        ensure!(same(read, &sent), "image {seconds} arrived changed");
    }
    Ok(())
}
