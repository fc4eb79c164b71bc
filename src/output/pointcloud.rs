//! `foxglove.PointCloud` as protobuf: the message types (prost) and the
//! FileDescriptorSet embedded as the MCAP schema, so Foxglove and the Python
//! reader decode frames with no setup. Field numbers and types follow the
//! published foxglove schemas (PointCloud, PackedElementField, Pose, Vector3,
//! Quaternion, google.protobuf.Timestamp).

use super::Field;
use super::Values;
use prost::Message;
use prost_types::field_descriptor_proto::{Label, Type};
use prost_types::{
    DescriptorProto, EnumDescriptorProto, EnumValueDescriptorProto, FieldDescriptorProto,
    FileDescriptorProto, FileDescriptorSet,
};

pub const SCHEMA_NAME: &str = "foxglove.PointCloud";

#[derive(Clone, PartialEq, Message)]
pub struct Vector3 {
    #[prost(double, tag = "1")]
    pub x: f64,
    #[prost(double, tag = "2")]
    pub y: f64,
    #[prost(double, tag = "3")]
    pub z: f64,
}

#[derive(Clone, PartialEq, Message)]
pub struct Quaternion {
    #[prost(double, tag = "1")]
    pub x: f64,
    #[prost(double, tag = "2")]
    pub y: f64,
    #[prost(double, tag = "3")]
    pub z: f64,
    #[prost(double, tag = "4")]
    pub w: f64,
}

#[derive(Clone, PartialEq, Message)]
pub struct Pose {
    #[prost(message, optional, tag = "1")]
    pub position: Option<Vector3>,
    #[prost(message, optional, tag = "2")]
    pub orientation: Option<Quaternion>,
}

/// foxglove.PackedElementField.NumericType values used here.
pub const UINT32: i32 = 5;
pub const FLOAT32: i32 = 7;

#[derive(Clone, PartialEq, Message)]
pub struct PackedElementField {
    #[prost(string, tag = "1")]
    pub name: String,
    #[prost(fixed32, tag = "2")]
    pub offset: u32,
    #[prost(int32, tag = "3")]
    pub r#type: i32,
}

#[derive(Clone, PartialEq, Message)]
pub struct PointCloud {
    #[prost(message, optional, tag = "1")]
    pub timestamp: Option<prost_types::Timestamp>,
    #[prost(string, tag = "2")]
    pub frame_id: String,
    #[prost(message, optional, tag = "3")]
    pub pose: Option<Pose>,
    #[prost(fixed32, tag = "4")]
    pub point_stride: u32,
    #[prost(message, repeated, tag = "5")]
    pub fields: Vec<PackedElementField>,
    #[prost(bytes = "vec", tag = "6")]
    pub data: Vec<u8>,
}

/// Encode one frame: every field packed little-endian, 4 bytes each, per point.
pub fn encode_frame(time: f64, fields: &[Field]) -> Vec<u8> {
    let n = fields.first().map_or(0, |f| f.values.len());
    let stride = 4 * fields.len();
    let mut data = vec![0u8; n * stride];
    for (k, f) in fields.iter().enumerate() {
        for i in 0..n {
            let o = i * stride + 4 * k;
            data[o..o + 4].copy_from_slice(&f.values.le_bytes(i));
        }
    }
    let secs = time.floor();
    let msg = PointCloud {
        timestamp: Some(prost_types::Timestamp {
            seconds: secs as i64,
            nanos: (((time - secs) * 1e9).round() as i32).min(999_999_999),
        }),
        frame_id: "world".into(),
        pose: Some(Pose {
            position: Some(Vector3 {
                x: 0.0,
                y: 0.0,
                z: 0.0,
            }),
            orientation: Some(Quaternion {
                x: 0.0,
                y: 0.0,
                z: 0.0,
                w: 1.0,
            }),
        }),
        point_stride: stride as u32,
        fields: fields
            .iter()
            .enumerate()
            .map(|(k, f)| PackedElementField {
                name: f.name.to_string(),
                offset: 4 * k as u32,
                r#type: match f.values {
                    Values::F32(_) => FLOAT32,
                    Values::U32(_) => UINT32,
                },
            })
            .collect(),
        data,
    };
    msg.encode_to_vec()
}

fn field(
    name: &str,
    number: i32,
    ty: Type,
    type_name: Option<&str>,
    repeated: bool,
) -> FieldDescriptorProto {
    FieldDescriptorProto {
        name: Some(name.into()),
        number: Some(number),
        label: Some(if repeated {
            Label::Repeated
        } else {
            Label::Optional
        } as i32),
        r#type: Some(ty as i32),
        type_name: type_name.map(str::to_string),
        json_name: Some(name.into()),
        ..Default::default()
    }
}

fn message(name: &str, fields: Vec<FieldDescriptorProto>) -> DescriptorProto {
    DescriptorProto {
        name: Some(name.into()),
        field: fields,
        ..Default::default()
    }
}

fn file(
    name: &str,
    package: &str,
    deps: &[&str],
    messages: Vec<DescriptorProto>,
) -> FileDescriptorProto {
    FileDescriptorProto {
        name: Some(name.into()),
        package: Some(package.into()),
        dependency: deps.iter().map(|d| d.to_string()).collect(),
        message_type: messages,
        syntax: Some("proto3".into()),
        ..Default::default()
    }
}

/// The serialized FileDescriptorSet for `foxglove.PointCloud` and its dependencies.
pub fn schema_descriptor_set() -> Vec<u8> {
    use Type::*;
    let numeric_names = [
        "UNKNOWN", "UINT8", "INT8", "UINT16", "INT16", "UINT32", "INT32", "FLOAT32", "FLOAT64",
    ];
    let mut packed = message(
        "PackedElementField",
        vec![
            field("name", 1, String, None, false),
            field("offset", 2, Fixed32, None, false),
            field(
                "type",
                3,
                Enum,
                Some(".foxglove.PackedElementField.NumericType"),
                false,
            ),
        ],
    );
    packed.enum_type.push(EnumDescriptorProto {
        name: Some("NumericType".into()),
        value: numeric_names
            .iter()
            .enumerate()
            .map(|(i, n)| EnumValueDescriptorProto {
                name: Some(n.to_string()),
                number: Some(i as i32),
                ..Default::default()
            })
            .collect(),
        ..Default::default()
    });
    let xyz = |names: &[&str]| -> Vec<FieldDescriptorProto> {
        names
            .iter()
            .enumerate()
            .map(|(i, n)| field(n, i as i32 + 1, Double, None, false))
            .collect()
    };
    let files = vec![
        file(
            "google/protobuf/timestamp.proto",
            "google.protobuf",
            &[],
            vec![message(
                "Timestamp",
                vec![
                    field("seconds", 1, Int64, None, false),
                    field("nanos", 2, Int32, None, false),
                ],
            )],
        ),
        file(
            "foxglove/Vector3.proto",
            "foxglove",
            &[],
            vec![message("Vector3", xyz(&["x", "y", "z"]))],
        ),
        file(
            "foxglove/Quaternion.proto",
            "foxglove",
            &[],
            vec![message("Quaternion", xyz(&["x", "y", "z", "w"]))],
        ),
        file(
            "foxglove/Pose.proto",
            "foxglove",
            &["foxglove/Quaternion.proto", "foxglove/Vector3.proto"],
            vec![message(
                "Pose",
                vec![
                    field("position", 1, Message, Some(".foxglove.Vector3"), false),
                    field(
                        "orientation",
                        2,
                        Message,
                        Some(".foxglove.Quaternion"),
                        false,
                    ),
                ],
            )],
        ),
        file(
            "foxglove/PackedElementField.proto",
            "foxglove",
            &[],
            vec![packed],
        ),
        file(
            "foxglove/PointCloud.proto",
            "foxglove",
            &[
                "foxglove/PackedElementField.proto",
                "foxglove/Pose.proto",
                "google/protobuf/timestamp.proto",
            ],
            vec![message(
                "PointCloud",
                vec![
                    field(
                        "timestamp",
                        1,
                        Message,
                        Some(".google.protobuf.Timestamp"),
                        false,
                    ),
                    field("frame_id", 2, String, None, false),
                    field("pose", 3, Message, Some(".foxglove.Pose"), false),
                    field("point_stride", 4, Fixed32, None, false),
                    field(
                        "fields",
                        5,
                        Message,
                        Some(".foxglove.PackedElementField"),
                        true,
                    ),
                    field("data", 6, Bytes, None, false),
                ],
            )],
        ),
    ];
    FileDescriptorSet { file: files }.encode_to_vec()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn frame_round_trips_through_prost() {
        let fields = vec![
            Field {
                name: "x",
                values: Values::F32(vec![1.5, -2.0]),
            },
            Field {
                name: "id",
                values: Values::U32(vec![7, 9]),
            },
        ];
        let bytes = encode_frame(1.25, &fields);
        let msg = PointCloud::decode(bytes.as_slice()).unwrap();
        assert_eq!(msg.point_stride, 8);
        assert_eq!(msg.frame_id, "world");
        assert_eq!(msg.timestamp.unwrap().nanos, 250_000_000);
        assert_eq!(&msg.data[8..12], &(-2.0f32).to_le_bytes());
        assert_eq!(&msg.data[12..16], &9u32.to_le_bytes());
        assert_eq!(msg.fields[1].r#type, UINT32);
    }

    #[test]
    fn descriptor_set_names_every_dependency() {
        let set = FileDescriptorSet::decode(schema_descriptor_set().as_slice()).unwrap();
        let names: Vec<_> = set.file.iter().map(|f| f.name().to_string()).collect();
        for f in &set.file {
            for d in &f.dependency {
                assert!(names.contains(d), "{} depends on missing {d}", f.name());
            }
        }
    }
}
