"""Rotation helpers for the script tests' synthetic ground truth."""
import numpy as np


def quaternion_xyzw(R):
    """Quaternions (x, y, z, w) of rotation matrices, from the largest of the four diagonal
    combinations: near 180 degrees w alone loses its digits."""
    out = np.empty((len(R), 4))
    d = np.stack([R[:, 0, 0], R[:, 1, 1], R[:, 2, 2], np.trace(R, axis1=1, axis2=2)], 1)
    pick = np.argmax(d, 1)
    for n, (m, i) in enumerate(zip(R, pick)):
        if i == 3:
            w = np.sqrt(1 + d[n, 3]) / 2
            q = [(m[2, 1] - m[1, 2]) / (4 * w), (m[0, 2] - m[2, 0]) / (4 * w),
                 (m[1, 0] - m[0, 1]) / (4 * w), w]
        else:
            j, k = (i + 1) % 3, (i + 2) % 3
            r = np.sqrt(1 + m[i, i] - m[j, j] - m[k, k])
            q = [0.0, 0.0, 0.0, (m[k, j] - m[j, k]) / (2 * r)]
            q[i], q[j], q[k] = r / 2, (m[j, i] + m[i, j]) / (2 * r), (m[k, i] + m[i, k]) / (2 * r)
        out[n] = q
    return out
