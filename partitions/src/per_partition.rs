//! [`PerPartition`]: one value per partition, indexed by the contracts' `Partition`. Every
//! table of the configuration that has a section per partition (`[ipc.idle.<partition>]`,
//! `[realtime.<partition>]`, `[isolation.<partition>]`) is one of these, read and written with
//! the partitions' binary names as keys (`Partition::binary`, the names users type), so that a
//! new partition is one variant of `Partition` and no table to extend by hand.

use std::fmt;
use std::marker::PhantomData;
use std::ops::{Index, IndexMut};

use missionlink_interfaces::contracts::Partition;
use serde::de::{self, DeserializeSeed, MapAccess, Visitor};
use serde::ser::SerializeMap;
use serde::{Deserialize, Deserializer, Serialize, Serializer};

/// The value a table gives a partition its file does not name.
pub trait PartitionDefault {
    /// The default of `partition`.
    fn default_for(partition: Partition) -> Self;
}

/// One `T` per partition.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct PerPartition<T> {
    voting_monitoring: T,
    mission_data_handling: T,
    system_automation: T,
    guidance: T,
}

impl<T> PerPartition<T> {
    /// The value `f` gives each partition.
    pub fn from_fn(mut f: impl FnMut(Partition) -> T) -> Self {
        Self {
            voting_monitoring: f(Partition::VotingMonitoring),
            mission_data_handling: f(Partition::MissionDataHandling),
            system_automation: f(Partition::SystemAutomation),
            guidance: f(Partition::Guidance),
        }
    }

    /// Each partition with its value, in start order.
    pub fn iter(&self) -> impl Iterator<Item = (Partition, &T)> {
        Partition::ALL.into_iter().map(move |p| (p, &self[p]))
    }
}

impl<T: Clone> PerPartition<T> {
    /// The same value for every partition.
    pub fn all(value: T) -> Self {
        Self::from_fn(|_| value.clone())
    }
}

impl<T> Index<Partition> for PerPartition<T> {
    type Output = T;

    fn index(&self, p: Partition) -> &T {
        match p {
            Partition::VotingMonitoring => &self.voting_monitoring,
            Partition::MissionDataHandling => &self.mission_data_handling,
            Partition::SystemAutomation => &self.system_automation,
            Partition::Guidance => &self.guidance,
        }
    }
}

impl<T> IndexMut<Partition> for PerPartition<T> {
    fn index_mut(&mut self, p: Partition) -> &mut T {
        match p {
            Partition::VotingMonitoring => &mut self.voting_monitoring,
            Partition::MissionDataHandling => &mut self.mission_data_handling,
            Partition::SystemAutomation => &mut self.system_automation,
            Partition::Guidance => &mut self.guidance,
        }
    }
}

impl<T: PartitionDefault> Default for PerPartition<T> {
    fn default() -> Self {
        Self::from_fn(T::default_for)
    }
}

/// A table of the configuration: the binary names as keys, every partition written.
impl<T: Serialize> Serialize for PerPartition<T> {
    fn serialize<S: Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        let mut map = serializer.serialize_map(Some(Partition::ALL.len()))?;
        for (p, value) in self.iter() {
            map.serialize_entry(p.binary(), value)?;
        }
        map.end()
    }
}

/// A key of the table: a partition by its binary name.
struct Key;

impl<'de> DeserializeSeed<'de> for Key {
    type Value = Partition;

    fn deserialize<D: Deserializer<'de>>(self, deserializer: D) -> Result<Partition, D::Error> {
        deserializer.deserialize_identifier(self)
    }
}

impl Visitor<'_> for Key {
    type Value = Partition;

    fn expecting(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str("the name of a partition")
    }

    fn visit_str<E: de::Error>(self, name: &str) -> Result<Partition, E> {
        Partition::from_binary(name).ok_or_else(|| E::unknown_field(name, &Partition::BINARIES))
    }
}

/// A table of the configuration: a partition it does not name keeps its default
/// ([`PartitionDefault`]); a key that names no partition, or one named twice, is refused.
impl<'de, T: Deserialize<'de> + PartitionDefault> Deserialize<'de> for PerPartition<T> {
    fn deserialize<D: Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        struct Table<T>(PhantomData<T>);

        impl<'de, T: Deserialize<'de> + PartitionDefault> Visitor<'de> for Table<T> {
            type Value = PerPartition<T>;

            fn expecting(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
                f.write_str("a table per partition")
            }

            fn visit_map<A: MapAccess<'de>>(self, mut map: A) -> Result<Self::Value, A::Error> {
                let mut table = PerPartition::<T>::default();
                let mut seen = PerPartition::all(false);
                while let Some(p) = map.next_key_seed(Key)? {
                    if std::mem::replace(&mut seen[p], true) {
                        return Err(de::Error::duplicate_field(p.binary()));
                    }
                    table[p] = map.next_value()?;
                }
                Ok(table)
            }
        }

        deserializer.deserialize_map(Table(PhantomData))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
    struct Number(u32);

    impl PartitionDefault for Number {
        fn default_for(p: Partition) -> Self {
            Number(if p == Partition::Guidance { 7 } else { 0 })
        }
    }

    #[test]
    fn each_partition_has_its_own_value() {
        let table = PerPartition::from_fn(Partition::binary);
        for p in Partition::ALL {
            assert_eq!(table[p], p.binary());
        }
        let order: Vec<_> = table.iter().map(|(p, _)| p).collect();
        assert_eq!(order, Partition::ALL);
    }

    #[test]
    fn a_table_is_keyed_by_the_binary_names_and_keeps_the_defaults_it_does_not_name() {
        let table: PerPartition<Number> = toml::from_str("voting-monitoring = 3\n").unwrap();
        assert_eq!(table[Partition::VotingMonitoring], Number(3));
        assert_eq!(table[Partition::Guidance], Number(7));
        let text = toml::to_string(&table).unwrap();
        assert!(text.contains("guidance-stub = 7"), "{text}");
        assert_eq!(
            toml::from_str::<PerPartition<Number>>(&text).unwrap(),
            table
        );
        let e = toml::from_str::<PerPartition<Number>>("guidance = 1\n").unwrap_err();
        assert!(e.to_string().contains("guidance-stub"), "{e}");
    }
}
