"""Ouster recordings: a packet capture (.pcap) with its sensor metadata (.json), an OSF file
(Ouster's own format: frames and metadata, no IMU), or a ROS bag of raw ouster-ros packets
(lidar_packets, imu_packets and metadata topics). Packets are decoded by
the `ouster-sdk` package (its packet formats, frame batcher and XYZ lookup table); the bag itself
is read with `rosbags`.

Points are in the sensor frame (Ouster's lidar_to_sensor applied, metres), each with the
timestamp of its measurement column; scans span their first to last valid column. IMU samples
(m/s^2, rad/s, in the IMU frame) come from the IMU packets, on the sensor clock of the columns;
T_imu_lidar is the inverse of the metadata's imu_to_sensor_transform (mm converted to m).

The recording is passed twice: at opening (IMU samples and the number of complete frames) and
then sequentially for the scans, so that a long capture is never held in memory.
"""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path
from typing import Any

import numpy as np

import farlio
from farlio._core import NS_PER_S

from .base import Dataset, LoadOptions
from .rosbag import OUSTER_PACKET_TYPES, bag_messages, describe_topics, is_bag_path, open_bag

PCAP_SUFFIX = ".pcap"
OSF_SUFFIX = ".osf"
MM_PER_M = 1000.0
#: measurement-block status bit that marks a valid column
COLUMN_VALID = 0x1
LIDAR_TOPIC_PART, IMU_TOPIC_PART, METADATA_TOPIC_PART = "lidar_packets", "imu_packets", "metadata"
METADATA_TYPE = "std_msgs/msg/String"


def _sdk() -> Any:
    try:
        from ouster.sdk import core
    except ImportError:
        raise ValueError(
            "reading Ouster recordings needs the 'ouster-sdk' package: pip install ouster-sdk "
            "(or pip install 'farlio[ouster]')"
        ) from None
    return core


def _bag_packet_topics(reader: Any) -> dict[str, list[str]]:
    out: dict[str, list[str]] = {LIDAR_TOPIC_PART: [], IMU_TOPIC_PART: [], METADATA_TOPIC_PART: []}
    for c in reader.connections:
        for part in out:
            wanted = METADATA_TYPE if part == METADATA_TOPIC_PART else None
            if part in c.topic and (c.msgtype == wanted if wanted else c.msgtype in OUSTER_PACKET_TYPES):
                if c.topic not in out[part]:
                    out[part].append(c.topic)
    return out


class OusterRecording(Dataset):
    """An Ouster .pcap (+ .json metadata) or a ROS bag of ouster-ros packets."""

    @classmethod
    def matches(cls, path: Path) -> bool:
        path = Path(path)
        if path.is_file() and path.suffix in (PCAP_SUFFIX, OSF_SUFFIX):
            return True
        if not is_bag_path(path):
            return False
        try:
            reader = open_bag(path)
        except ValueError:
            return False  # the ROS bag loader reports why
        try:
            return bool(_bag_packet_topics(reader)[LIDAR_TOPIC_PART])
        finally:
            reader.close()

    def __init__(self, path: Path, options: LoadOptions | None = None):
        self.path = Path(path)
        self.options = options or LoadOptions()
        self._core = _sdk()
        if self.path.suffix == PCAP_SUFFIX:
            self.meta_path = self._find_meta()
            self.info = self._parse_meta(self.meta_path.read_text(), str(self.meta_path))
        elif self.path.suffix == OSF_SUFFIX:
            self.info = self._osf_source().sensor_info[0]
        else:
            self._open_bag()
        self._pf = self._core.PacketFormat(self.info)
        self._lut = self._core.XYZLut(self.info, use_extrinsics=False)
        self._imu: list[farlio.ImuSample] = []
        self._count = 0
        for item in self._frames():
            if isinstance(item, farlio.ImuSample):
                self._imu.append(item)
            else:
                self._count += 1
        if self._count == 0:
            raise ValueError(
                f"{self.path}: no complete LiDAR frame in the recording "
                f"({self.info.format.columns_per_frame} columns x {self.info.format.pixels_per_column} "
                f"beams expected from the metadata)"
            )
        self._imu.sort(key=lambda s: s.stamp_ns)
        self._gen: Iterator[farlio.Scan] | None = None
        self._next = 0

    # --- metadata and sources ---------------------------------------------------------------------
    def _find_meta(self) -> Path:
        if self.options.meta is not None:
            return Path(self.options.meta)
        same = self.path.with_suffix(".json")
        if same.exists():
            return same
        jsons = sorted(self.path.parent.glob("*.json"))
        # Ouster names captures <sensor>_<version>_<mode>[_suffix].pcap beside <sensor>_<version>_<mode>.json
        prefixed = [j for j in jsons if self.path.stem.startswith(j.stem)]
        if len(prefixed) == 1:
            return prefixed[0]
        if len(jsons) == 1:
            return jsons[0]
        raise ValueError(
            f"{self.path}: no sensor metadata: expected {same.name} or one .json beside it (found "
            f"{', '.join(j.name for j in jsons) or 'none'}); pass --meta FILE.json"
        )

    def _parse_meta(self, text: str, where: str) -> Any:
        try:
            return self._core.SensorInfo(text)
        except Exception as e:  # the SDK raises RuntimeError/ValueError on bad metadata
            raise ValueError(f"{where}: not valid Ouster sensor metadata ({e})") from None

    def _open_bag(self) -> None:
        self._reader = open_bag(self.path)
        topics = _bag_packet_topics(self._reader)
        lidar = topics[LIDAR_TOPIC_PART]
        if self.options.lidar_topics:
            wanted = self.options.lidar_topics
            if len(wanted) > 1 or wanted[0] not in lidar:
                raise ValueError(
                    f"{self.path}: --lidar-topic {' '.join(wanted)}: expected one Ouster lidar_packets "
                    f"topic of: {', '.join(lidar)} (merging several Ouster sensors from packets is not "
                    f"supported; convert to PointCloud2)"
                )
            lidar = list(wanted)
        if len(lidar) != 1:
            raise ValueError(
                f"{self.path}: {len(lidar)} Ouster lidar_packets topics ({', '.join(lidar)}): pass --lidar-topic"
            )
        ns = lidar[0][: -len(LIDAR_TOPIC_PART)]
        self.lidar_topic = lidar[0]
        imu = [t for t in topics[IMU_TOPIC_PART] if t.startswith(ns)]
        self.imu_topic = (
            None if self.options.imu_topic == "none" else (self.options.imu_topic or (imu[0] if imu else None))
        )
        meta = [t for t in topics[METADATA_TOPIC_PART] if t.startswith(ns)]
        if self.options.meta is not None:
            self.info = self._parse_meta(Path(self.options.meta).read_text(), str(self.options.meta))
        elif not meta:
            raise ValueError(
                f"{self.path}: no Ouster metadata topic ({ns}{METADATA_TOPIC_PART}, {METADATA_TYPE}) "
                f"beside {self.lidar_topic}; topics: {describe_topics(self._reader)}; pass --meta FILE.json"
            )
        else:
            conns = [c for c in self._reader.connections if c.topic == meta[0]]
            msg = next((m for _, _, m in bag_messages(self._reader, self.path, conns)), None)
            if msg is None:
                raise ValueError(f"{self.path}: topic {meta[0]} has no message")
            self.info = self._parse_meta(msg.data, f"{self.path} topic {meta[0]}")

    def _osf_source(self) -> Any:
        from ouster.sdk.osf import OsfFrameSetSource

        try:
            return OsfFrameSetSource(str(self.path))
        except Exception as e:  # the SDK raises RuntimeError on a bad file
            raise ValueError(f"{self.path}: cannot read as an Ouster OSF file ({e})") from None

    def _packets(self) -> Iterator[Any]:
        core = self._core
        if self.path.suffix == PCAP_SUFFIX:
            from ouster.sdk.pcap import PcapPacketSource

            try:
                source = PcapPacketSource(str(self.path), meta=[str(self.meta_path)])
            except Exception as e:
                raise ValueError(f"{self.path}: cannot read the capture with {self.meta_path.name} ({e})") from None
            for _, packet in source:
                yield packet
            return
        topics = {self.lidar_topic: core.LidarPacket, self.imu_topic: core.ImuPacket}
        conns = [c for c in self._reader.connections if c.topic in topics]
        for conn, t, msg in bag_messages(self._reader, self.path, conns):
            packet = topics[conn.topic](self._pf)
            size = len(packet.buf)
            if len(msg.buf) < size:
                raise ValueError(
                    f"{self.path}: topic {conn.topic}: packet at {t} ns has {len(msg.buf)} bytes; the "
                    f"metadata's format needs {size}"
                )
            packet.buf[:] = msg.buf[:size]
            packet.host_timestamp = t
            yield packet

    # --- frames to scans -----------------------------------------------------------------------------
    def _frames(self) -> Iterator[Any]:
        """IMU samples and complete LidarFrames, in recording order."""
        core = self._core
        if self.path.suffix == OSF_SUFFIX:  # frames already batched; the first sensor of each set
            for frame_set in self._osf_source():
                for frame in frame_set:
                    if frame is not None:
                        yield frame
                    break
            return
        batcher = core.FrameBatcher(self.info)
        frame = core.LidarFrame(self.info)
        for packet in self._packets():
            if isinstance(packet, core.ImuPacket):
                stamps, acc, gyro = packet.timestamp(), packet.accel(), packet.gyro()
                for k in range(len(stamps)):
                    yield farlio.ImuSample(
                        int(stamps[k]), np.asarray(gyro[k], np.float64), np.asarray(acc[k], np.float64)
                    )
            elif isinstance(packet, core.LidarPacket) and batcher.batch(packet, frame):
                yield frame
                frame = core.LidarFrame(self.info)

    def _to_scan(self, frame: Any) -> farlio.Scan:
        core = self._core
        valid_cols = (np.asarray(frame.status) & COLUMN_VALID).astype(bool)
        stamps = np.asarray(frame.timestamp).astype(np.int64)
        rng = np.asarray(frame.field(core.ChanField.RANGE))
        keep = (rng > 0) & valid_cols[None, :]
        if not valid_cols.any():
            raise ValueError(f"{self.path}: frame {frame.frame_id} has no valid column")
        start, end = int(stamps[valid_cols].min()), int(stamps[valid_cols].max())
        xyz = self._lut(frame)[keep].astype(np.float32)
        t = ((np.broadcast_to(stamps[None, :], rng.shape)[keep] - start) / NS_PER_S).astype(np.float32)
        intensity = None
        if frame.has_field(core.ChanField.REFLECTIVITY):
            intensity = np.asarray(frame.field(core.ChanField.REFLECTIVITY))[keep].astype(np.float32)
        return farlio.Scan(
            np.ascontiguousarray(xyz), time_s=t, intensity=intensity, start_stamp_ns=start, end_stamp_ns=end
        )

    # --- Dataset ---------------------------------------------------------------------------------------
    def __len__(self) -> int:
        return self._count

    def scan(self, i: int) -> farlio.Scan:
        if self._gen is None or i < self._next:
            self._gen = (f for f in self._frames() if not isinstance(f, farlio.ImuSample))
            self._next = 0
        frame = None
        while self._next <= i:
            frame = next(self._gen, None)
            if frame is None:
                raise ValueError(f"{self.path}: only {self._next} frames (scan {i} asked)")
            self._next += 1
        scan = self._to_scan(frame)
        farlio._core.io.check_point_times(scan, self.scan_source(i))  # the check of every loader
        return scan

    def scan_source(self, i: int) -> str:
        return f"{self.path} frame {i}"

    def imu(self) -> list[farlio.ImuSample]:
        return [] if self.options.imu_topic == "none" else self._imu

    def T_imu_lidar(self) -> farlio.SE3:
        m = np.array(self.info.imu_to_sensor_transform, dtype=np.float64)
        m[:3, 3] /= MM_PER_M
        return farlio.SE3.from_matrix(m).inverse()
