"""image_geometry: the pinhole and stereo camera models of a sensor_msgs/CameraInfo.

``PinholeCameraModel.fromCameraInfo(msg)`` reads K, D, R, P, the binning and the region of
interest (an all-zero ROI is the full image) and adjusts K and P to them, as ROS's module does;
then ``project3dToPixel``, ``projectPixelTo3dRay``, ``rectifyPoint`` and ``rectifyImage``
(OpenCV), the focal lengths, centres and fields of view. The matrices are ``numpy.matrix``
objects, as in ROS, so code that multiplies them with ``*`` keeps its meaning. ``rectifyImage``
computes its undistortion maps once per CameraInfo instead of on every call.
``StereoCameraModel`` pairs two models and adds the disparity-to-depth matrix ``Q``.
"""

from __future__ import annotations

import copy
import math
from typing import Any, Optional, Sequence, Tuple

import numpy

__all__ = ["PinholeCameraModel", "StereoCameraModel", "mkmat"]


def mkmat(rows: int, cols: int, values: Sequence[float]) -> numpy.matrix:
    """A rows x cols float64 ``numpy.matrix`` of ``values`` row by row, cut or padded with
    zeros to size (ROS's helper)."""
    flat = numpy.zeros(rows * cols)
    data = numpy.asarray(values, dtype=numpy.float64).reshape(-1)[:rows * cols]
    flat[:data.shape[0]] = data
    # a view, not numpy.matrix(...): the constructor warns that the class is discouraged
    return flat.reshape(rows, cols).view(numpy.matrix)


class PinholeCameraModel:
    """An idealised monocular camera (see the module's text)."""

    def __init__(self) -> None:
        self.K: Optional[numpy.matrix] = None
        self.D: Optional[numpy.matrix] = None
        self.R: Optional[numpy.matrix] = None
        self.P: Optional[numpy.matrix] = None
        self.full_K: Optional[numpy.matrix] = None
        self.full_P: Optional[numpy.matrix] = None
        self.width: Optional[int] = None
        self.height: Optional[int] = None
        self.binning_x: Optional[int] = None
        self.binning_y: Optional[int] = None
        self.raw_roi: Any = None
        self.tf_frame: Optional[str] = None
        self.stamp: Any = None
        self.mapx: Optional[numpy.ndarray] = None
        self.mapy: Optional[numpy.ndarray] = None

    def fromCameraInfo(self, msg: Any) -> None:  # noqa: N802 (ROS's names)
        """Set the parameters from a sensor_msgs/CameraInfo."""
        self.K = mkmat(3, 3, msg.K)
        self.D = mkmat(len(msg.D), 1, msg.D) if len(msg.D) else None
        self.R = mkmat(3, 3, msg.R)
        self.P = mkmat(3, 4, msg.P)
        self.full_K = mkmat(3, 3, msg.K)
        self.full_P = mkmat(3, 4, msg.P)
        self.width = msg.width
        self.height = msg.height
        self.binning_x = max(1, msg.binning_x)
        self.binning_y = max(1, msg.binning_y)
        self.resolution = (msg.width, msg.height)
        self.raw_roi = copy.copy(msg.roi)
        roi = self.raw_roi
        if roi.x_offset == 0 and roi.y_offset == 0 and roi.width == 0 and roi.height == 0:
            roi.width, roi.height = self.width, self.height
        self.tf_frame = msg.header.frame_id
        self.stamp = msg.header.stamp
        for m in (self.K, self.P):
            m[0, 0] /= self.binning_x
            m[1, 1] /= self.binning_y
            m[0, 2] = (m[0, 2] - roi.x_offset) / self.binning_x
            m[1, 2] = (m[1, 2] - roi.y_offset) / self.binning_y
        self.mapx = self.mapy = None

    def _maps(self) -> Tuple[numpy.ndarray, numpy.ndarray]:
        import cv2

        if self.mapx is None or self.mapy is None:
            self.mapx, self.mapy = cv2.initUndistortRectifyMap(
                self.K, self.D, self.R, self.P, (self.width, self.height), cv2.CV_32FC1)
        return self.mapx, self.mapy

    def rectifyImage(self, raw: numpy.ndarray, rectified: numpy.ndarray) -> None:  # noqa: N802
        """Undistort and rectify image ``raw`` into ``rectified`` (an array of the same shape
        and type), with bicubic interpolation."""
        import cv2

        mapx, mapy = self._maps()
        cv2.remap(raw, mapx, mapy, cv2.INTER_CUBIC, rectified)

    def rectifyPoint(self, uv_raw: Sequence[float]) -> numpy.ndarray:  # noqa: N802
        """The rectified pixel of raw pixel ``(u, v)``."""
        import cv2

        src = numpy.array(list(uv_raw), dtype=numpy.float64).reshape(1, 1, 2)
        return cv2.undistortPoints(src, self.K, self.D, R=self.R, P=self.P)[0, 0]

    def project3dToPixel(self, point: Sequence[float]) -> Tuple[float, float]:  # noqa: N802
        """The rectified pixel ``(u, v)`` of 3-D point ``(x, y, z)`` (nan, nan behind w = 0)."""
        x, y, w = (numpy.asarray(self.P) @ [point[0], point[1], point[2], 1.0]).tolist()
        if w != 0:
            return x / w, y / w
        return float("nan"), float("nan")

    def projectPixelTo3dRay(self, uv: Sequence[float]) -> Tuple[float, float, float]:  # noqa: N802
        """The unit vector from the camera centre through rectified pixel ``(u, v)``."""
        x = (uv[0] - self.cx()) / self.fx()
        y = (uv[1] - self.cy()) / self.fy()
        norm = math.sqrt(x * x + y * y + 1)
        return x / norm, y / norm, 1.0 / norm

    def getDeltaU(self, deltaX: float, Z: float) -> float:  # noqa: N802, N803
        """The pixel width of ``deltaX`` at depth ``Z`` (inf at Z = 0)."""
        return float("inf") if Z == 0 else self.fx() * deltaX / Z

    def getDeltaV(self, deltaY: float, Z: float) -> float:  # noqa: N802, N803
        """The pixel height of ``deltaY`` at depth ``Z`` (inf at Z = 0)."""
        return float("inf") if Z == 0 else self.fy() * deltaY / Z

    def getDeltaX(self, deltaU: float, Z: float) -> float:  # noqa: N802, N803
        """The width at depth ``Z`` of ``deltaU`` pixels."""
        return Z * deltaU / self.fx()

    def getDeltaY(self, deltaV: float, Z: float) -> float:  # noqa: N802, N803
        """The height at depth ``Z`` of ``deltaV`` pixels."""
        return Z * deltaV / self.fy()

    def fullResolution(self) -> Tuple[int, int]:  # noqa: N802
        return self.resolution

    def intrinsicMatrix(self) -> numpy.matrix:  # noqa: N802
        """K (``camera_matrix`` in OpenCV's words), adjusted for binning and ROI."""
        return self.K

    def distortionCoeffs(self) -> numpy.matrix:  # noqa: N802
        return self.D

    def rotationMatrix(self) -> numpy.matrix:  # noqa: N802
        return self.R

    def projectionMatrix(self) -> numpy.matrix:  # noqa: N802
        return self.P

    def fullIntrinsicMatrix(self) -> numpy.matrix:  # noqa: N802
        """K as the CameraInfo gave it (full resolution)."""
        return self.full_K

    def fullProjectionMatrix(self) -> numpy.matrix:  # noqa: N802
        return self.full_P

    def cx(self) -> float:
        return self.P[0, 2]

    def cy(self) -> float:
        return self.P[1, 2]

    def fx(self) -> float:
        return self.P[0, 0]

    def fy(self) -> float:
        return self.P[1, 1]

    def Tx(self) -> float:  # noqa: N802
        """P's x translation term (-fx * baseline for a right stereo camera)."""
        return self.P[0, 3]

    def Ty(self) -> float:  # noqa: N802
        return self.P[1, 3]

    def fovX(self) -> float:  # noqa: N802
        """The horizontal field of view in radians."""
        return 2 * math.atan(self.width / (2 * self.fx()))

    def fovY(self) -> float:  # noqa: N802
        """The vertical field of view in radians."""
        return 2 * math.atan(self.height / (2 * self.fy()))

    def tfFrame(self) -> Optional[str]:  # noqa: N802
        """The camera's frame (the CameraInfo's header.frame_id)."""
        return self.tf_frame


class StereoCameraModel:
    """A pair of rectified cameras: ``left``, ``right`` and the reprojection matrix ``Q``."""

    def __init__(self) -> None:
        self.left = PinholeCameraModel()
        self.right = PinholeCameraModel()

    def fromCameraInfo(self, left_msg: Any, right_msg: Any) -> None:  # noqa: N802
        """Set both cameras from their CameraInfo messages."""
        self.left.fromCameraInfo(left_msg)
        self.right.fromCameraInfo(right_msg)
        assert self.right.P is not None
        fx = self.right.P[0, 0]
        cx = self.right.P[0, 2]
        cy = self.right.P[1, 2]
        tx = -self.right.P[0, 3] / fx
        # Q maps (u, v, disparity, 1) to homogeneous 3-D coordinates
        self.Q = numpy.zeros((4, 4), dtype="float64")
        self.Q[0, 0] = 1.0
        self.Q[0, 3] = -cx
        self.Q[1, 1] = 1.0
        self.Q[1, 3] = -cy
        self.Q[2, 3] = fx
        self.Q[3, 2] = 1 / tx

    def tfFrame(self) -> Optional[str]:  # noqa: N802
        """The frame of the 3-D points: the left camera's."""
        return self.left.tfFrame()

    def project3dToPixel(self, point: Sequence[float]) -> Tuple[Tuple[float, float], Tuple[float, float]]:  # noqa: N802
        """((u_left, v_left), (u_right, v_right)) of 3-D point ``(x, y, z)``."""
        return self.left.project3dToPixel(point), self.right.project3dToPixel(point)

    def projectPixelTo3d(self, left_uv: Sequence[float], disparity: float  # noqa: N802
                         ) -> Tuple[float, float, float]:
        """The 3-D point of left pixel ``(u, v)`` at ``disparity`` pixels ((0, 0, 0) when the
        homogeneous coordinate is 0)."""
        x, y, z, w = (self.Q @ [left_uv[0], left_uv[1], disparity, 1.0]).tolist()
        if w != 0:
            return x / w, y / w, z / w
        return 0.0, 0.0, 0.0

    def getZ(self, disparity: float) -> float:  # noqa: N802
        """The depth of ``disparity`` pixels (inf at 0)."""
        if disparity == 0:
            return float("inf")
        assert self.right.P is not None
        return -self.right.P[0, 3] / disparity

    def getDisparity(self, Z: float) -> float:  # noqa: N802, N803
        """The disparity of depth ``Z`` (inf at 0)."""
        if Z == 0:
            return float("inf")
        assert self.right.P is not None
        return -self.right.P[0, 3] / Z
