//! The node's parameters, read-only, through ROS 2's parameter services as rclcpp serves them
//! (`/<node>/get_parameters`, `list_parameters`, `get_parameter_types`, `describe_parameters`,
//! `set_parameters`, `set_parameters_atomically`), so `ros2 param get /rover use_sim_time` and
//! `ros2 param list /rover` answer; and declared on `/parameter_events` as rclcpp declares a
//! node's parameters, to each subscriber when it matches (a subscriber that started first
//! hears them, which a write at the start would miss before discovery). rover's parameters: `use_sim_time` (true: every stamp rover publishes is sim time,
//! on `/clock`) and `robot_description` (the URDF, as robot_state_publisher's). Setting one
//! is refused with a reason: they describe the run, they do not steer it.

use crate::dds::{Writer, parameter_events_qos, writer};
use crate::error::Result;
use crate::msgs::{RosMessage, Time};
use rustdds::{
    DataWriterStatus, DomainParticipant, GUID, RTPSEntity, StatusEvented, WriteOptionsBuilder,
};
use serde::{Deserialize, Serialize};

use crate::services::{Server, ServiceType};

/// `rcl_interfaces/msg/ParameterType`'s values rover uses.
const PARAMETER_NOT_SET: u8 = 0;
const PARAMETER_BOOL: u8 = 1;
const PARAMETER_STRING: u8 = 4;

/// `rcl_interfaces/msg/ParameterValue`.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct ParameterValue {
    /// `ParameterType`: 0 not set, 1 bool, 2 integer, 3 double, 4 string, 5-9 arrays.
    #[serde(rename = "type")]
    pub kind: u8,
    /// With type 1.
    pub bool_value: bool,
    /// With type 2.
    pub integer_value: i64,
    /// With type 3.
    pub double_value: f64,
    /// With type 4.
    pub string_value: String,
    /// With type 5.
    pub byte_array_value: Vec<u8>,
    /// With type 6.
    pub bool_array_value: Vec<bool>,
    /// With type 7.
    pub integer_array_value: Vec<i64>,
    /// With type 8.
    pub double_array_value: Vec<f64>,
    /// With type 9.
    pub string_array_value: Vec<String>,
}

/// `rcl_interfaces/msg/Parameter`.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct Parameter {
    /// Its name.
    pub name: String,
    /// Its value.
    pub value: ParameterValue,
}

/// `rcl_interfaces/msg/SetParametersResult`.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct SetParametersResult {
    /// Whether it was set.
    pub successful: bool,
    /// Why not.
    pub reason: String,
}

/// `rcl_interfaces/msg/ParameterDescriptor` (its ranges empty).
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct ParameterDescriptor {
    /// Its name.
    pub name: String,
    /// Its type.
    #[serde(rename = "type")]
    pub kind: u8,
    /// What it is.
    pub description: String,
    /// Constraints, in words.
    pub additional_constraints: String,
    /// Whether it can be set.
    pub read_only: bool,
    /// Whether its type may change.
    pub dynamic_typing: bool,
    /// `FloatingPointRange[<=1]`: none.
    pub floating_point_range: Vec<()>,
    /// `IntegerRange[<=1]`: none.
    pub integer_range: Vec<()>,
}

/// `rcl_interfaces/srv/GetParameters`.
pub struct GetParameters;
impl ServiceType for GetParameters {
    type Request = Vec<String>;
    type Response = Vec<ParameterValue>;
    const REQUEST_TYPE: &'static str = "rcl_interfaces::srv::dds_::GetParameters_Request_";
    const RESPONSE_TYPE: &'static str = "rcl_interfaces::srv::dds_::GetParameters_Response_";
}

/// `rcl_interfaces/srv/GetParameterTypes`.
pub struct GetParameterTypes;
impl ServiceType for GetParameterTypes {
    type Request = Vec<String>;
    type Response = Vec<u8>;
    const REQUEST_TYPE: &'static str = "rcl_interfaces::srv::dds_::GetParameterTypes_Request_";
    const RESPONSE_TYPE: &'static str = "rcl_interfaces::srv::dds_::GetParameterTypes_Response_";
}

/// `rcl_interfaces/srv/ListParameters`: prefixes and a depth in; names and prefixes out.
pub struct ListParameters;
impl ServiceType for ListParameters {
    type Request = (Vec<String>, u64);
    type Response = (Vec<String>, Vec<String>);
    const REQUEST_TYPE: &'static str = "rcl_interfaces::srv::dds_::ListParameters_Request_";
    const RESPONSE_TYPE: &'static str = "rcl_interfaces::srv::dds_::ListParameters_Response_";
}

/// `rcl_interfaces/srv/DescribeParameters`.
pub struct DescribeParameters;
impl ServiceType for DescribeParameters {
    type Request = Vec<String>;
    type Response = Vec<ParameterDescriptor>;
    const REQUEST_TYPE: &'static str = "rcl_interfaces::srv::dds_::DescribeParameters_Request_";
    const RESPONSE_TYPE: &'static str = "rcl_interfaces::srv::dds_::DescribeParameters_Response_";
}

/// `rcl_interfaces/srv/SetParameters`.
pub struct SetParameters;
impl ServiceType for SetParameters {
    type Request = Vec<Parameter>;
    type Response = Vec<SetParametersResult>;
    const REQUEST_TYPE: &'static str = "rcl_interfaces::srv::dds_::SetParameters_Request_";
    const RESPONSE_TYPE: &'static str = "rcl_interfaces::srv::dds_::SetParameters_Response_";
}

/// `rcl_interfaces/srv/SetParametersAtomically`: all or none (rclpy's parameter client waits
/// for it with the others).
pub struct SetParametersAtomically;
impl ServiceType for SetParametersAtomically {
    type Request = Vec<Parameter>;
    type Response = SetParametersResult;
    const REQUEST_TYPE: &'static str =
        "rcl_interfaces::srv::dds_::SetParametersAtomically_Request_";
    const RESPONSE_TYPE: &'static str =
        "rcl_interfaces::srv::dds_::SetParametersAtomically_Response_";
}

/// `rcl_interfaces/msg/ParameterEvent`, on `/parameter_events`: what every rclcpp and rclpy
/// node publishes when its parameters are declared, changed or deleted.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct ParameterEvent {
    /// When.
    pub stamp: Time,
    /// The node's full name (`/rover`).
    pub node: String,
    /// Parameters declared.
    pub new_parameters: Vec<Parameter>,
    /// Parameters changed.
    pub changed_parameters: Vec<Parameter>,
    /// Parameters deleted.
    pub deleted_parameters: Vec<Parameter>,
}

impl RosMessage for ParameterEvent {
    const DDS_TYPE: &'static str = "rcl_interfaces::msg::dds_::ParameterEvent_";
    const DEFINITION: &'static str = crate::definitions::PARAMETER_EVENT;
}

/// The topic of every node's parameter events.
pub const PARAMETER_EVENTS_TOPIC: &str = "/parameter_events";

/// The node's parameters and their services.
pub struct Parameters {
    values: Vec<(&'static str, ParameterValue, &'static str)>,
    get: Server<GetParameters>,
    types: Server<GetParameterTypes>,
    list: Server<ListParameters>,
    describe: Server<DescribeParameters>,
    set: Server<SetParameters>,
    set_atomically: Server<SetParametersAtomically>,
    events: Writer<ParameterEvent>,
    declaration: ParameterEvent,
}

impl Parameters {
    /// Serves node `node`'s (`/rover`) parameters; `description`: the robot's URDF.
    pub fn serve(
        participant: &DomainParticipant,
        subscriber: &rustdds::Subscriber,
        publisher: &rustdds::Publisher,
        node: &str,
        description: &str,
    ) -> Result<Self> {
        let node = node.trim_end_matches('/');
        let name = |service: &str| format!("{node}/{service}");
        let values = vec![
            (
                "use_sim_time",
                ParameterValue {
                    kind: PARAMETER_BOOL,
                    bool_value: true,
                    ..ParameterValue::default()
                },
                "rover's stamps are sim time, on /clock",
            ),
            (
                "robot_description",
                ParameterValue {
                    kind: PARAMETER_STRING,
                    string_value: description.to_owned(),
                    ..ParameterValue::default()
                },
                "the robot's URDF, as robot_state_publisher has it",
            ),
        ];
        let events = writer::<ParameterEvent>(
            participant,
            publisher,
            PARAMETER_EVENTS_TOPIC,
            &parameter_events_qos(),
        )?;
        let declaration = ParameterEvent {
            stamp: Time::default(),
            node: node.to_owned(),
            new_parameters: values
                .iter()
                .map(|(name, value, _)| Parameter {
                    name: (*name).to_owned(),
                    value: value.clone(),
                })
                .collect(),
            ..ParameterEvent::default()
        };
        Ok(Self {
            events,
            declaration,
            values,
            get: Server::new(participant, subscriber, publisher, &name("get_parameters"))?,
            types: Server::new(
                participant,
                subscriber,
                publisher,
                &name("get_parameter_types"),
            )?,
            list: Server::new(participant, subscriber, publisher, &name("list_parameters"))?,
            describe: Server::new(
                participant,
                subscriber,
                publisher,
                &name("describe_parameters"),
            )?,
            set: Server::new(participant, subscriber, publisher, &name("set_parameters"))?,
            set_atomically: Server::new(
                participant,
                subscriber,
                publisher,
                &name("set_parameters_atomically"),
            )?,
        })
    }

    /// Answers the requests that came, and declares the parameters to each new subscriber of
    /// `/parameter_events`.
    pub fn poll(&mut self) {
        while let Some(status) = self.events.try_recv_status() {
            if let DataWriterStatus::PublicationMatched {
                current, reader, ..
            } = status
                && current.count_change() > 0
            {
                let only_it = WriteOptionsBuilder::new().to_single_reader(reader).build();
                if let Err(e) = self
                    .events
                    .write_with_options(self.declaration.clone(), only_it)
                {
                    tracing::warn!("ROS 2: {PARAMETER_EVENTS_TOPIC} could not be written ({e})");
                }
            }
        }
        let values = &self.values;
        let find = |name: &str| values.iter().find(|v| v.0 == name);
        self.get.serve(|names| {
            names
                .iter()
                .map(|n| find(n).map(|v| v.1.clone()).unwrap_or_default())
                .collect()
        });
        self.types.serve(|names| {
            names
                .iter()
                .map(|n| find(n).map_or(PARAMETER_NOT_SET, |v| v.1.kind))
                .collect()
        });
        self.list.serve(|(prefixes, _depth)| {
            let names = values
                .iter()
                .map(|v| v.0.to_owned())
                .filter(|n| {
                    prefixes.is_empty() || prefixes.iter().any(|p| n.starts_with(p.as_str()))
                })
                .collect();
            (names, Vec::new())
        });
        self.describe.serve(|names| {
            names
                .iter()
                .map(|n| ParameterDescriptor {
                    name: n.clone(),
                    kind: find(n).map_or(PARAMETER_NOT_SET, |v| v.1.kind),
                    description: find(n).map(|v| v.2.to_owned()).unwrap_or_default(),
                    read_only: true,
                    ..ParameterDescriptor::default()
                })
                .collect()
        });
        let refusal = |p: &Parameter| SetParametersResult {
            successful: false,
            reason: if find(&p.name).is_some() {
                format!("{} is read-only: it describes the run", p.name)
            } else {
                format!("rover has no parameter {}", p.name)
            },
        };
        self.set
            .serve(|parameters| parameters.iter().map(refusal).collect());
        self.set_atomically.serve(|parameters| {
            parameters
                .first()
                .map(refusal)
                .unwrap_or_else(|| SetParametersResult {
                    successful: false,
                    reason: "no parameters given".to_owned(),
                })
        });
    }

    /// The services' readers and writers and the events' writer, for `ros_discovery_info`.
    pub fn gids(&self) -> (Vec<GUID>, Vec<GUID>) {
        let (readers, mut writers): (Vec<GUID>, Vec<GUID>) = [
            self.get.gids(),
            self.types.gids(),
            self.list.gids(),
            self.describe.gids(),
            self.set.gids(),
            self.set_atomically.gids(),
        ]
        .into_iter()
        .unzip();
        writers.push(self.events.guid());
        (readers, writers)
    }
}
