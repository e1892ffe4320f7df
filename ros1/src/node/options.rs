//! Where a node runs and how others reach it ([`NodeOptions`]), and ROS names in the global
//! namespace ([`global_name`]).

use crate::error::{Error, Result};
use crate::xmlrpc;

/// Where the node runs and how others reach it.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct NodeOptions {
    /// Global node name (`/rover`).
    pub name: String,
    /// `ROS_MASTER_URI`.
    pub master_uri: String,
    /// The host name or address peers use to reach this node (`ROS_IP`, `ROS_HOSTNAME`).
    pub host: String,
}

impl NodeOptions {
    /// Options from the environment, as rospy reads it: `ROS_MASTER_URI` (default
    /// `http://localhost:11311`), `ROS_IP`, else `ROS_HOSTNAME`, else the machine's host name.
    pub fn from_env(name: &str) -> Result<Self> {
        let var = |k: &str| std::env::var(k).ok().filter(|v| !v.trim().is_empty());
        let master_uri = var("ROS_MASTER_URI").unwrap_or_else(|| "http://localhost:11311".into());
        xmlrpc::host_port(&master_uri)
            .map_err(|e| Error::Config(format!("ROS_MASTER_URI={master_uri}: {e}")))?;
        let host = var("ROS_IP")
            .or_else(|| var("ROS_HOSTNAME"))
            .or_else(|| {
                std::fs::read_to_string("/proc/sys/kernel/hostname")
                    .ok()
                    .map(|h| h.trim().to_owned())
                    .filter(|h| !h.is_empty())
            })
            .unwrap_or_else(|| "localhost".into());
        Ok(Self {
            name: global_name(name)?,
            master_uri,
            host,
        })
    }
}

/// A name in the global namespace: `rover` -> `/rover`. Rejects names ROS would reject.
pub fn global_name(name: &str) -> Result<String> {
    let trimmed = name.trim_start_matches('/');
    let ok = !trimmed.is_empty()
        && trimmed.split('/').all(|part| {
            part.chars()
                .next()
                .is_some_and(|c| c.is_ascii_alphabetic() || c == '_' || c == '~')
                && part
                    .chars()
                    .all(|c| c.is_ascii_alphanumeric() || c == '_' || c == '~')
        });
    if ok {
        Ok(format!("/{trimmed}"))
    } else {
        Err(Error::Config(format!(
            "{name:?} is not a valid ROS name (letters, digits, '_' and '/', starting with a letter)"
        )))
    }
}
