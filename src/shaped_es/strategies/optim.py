"""Tiny first-order optimizers applied to the ES gradient (ascent), with explicit, saveable state.

The paper's update, Eq. (4), is plain gradient ascent with step ``gamma * beta``; :class:`SGD` with
``momentum=0`` is exactly that with ``lr = gamma * beta``. :class:`Adam` is the common choice for ES on
neural-network policies (Salimans et al. 2017 use Adam). Both keep every bit of state in numpy arrays so
a checkpoint resumes bit for bit. The steps update their state in place (the same operations in the same
order as the formulas, so the same bits) to spare large policies the temporaries.
"""

from __future__ import annotations

import numpy as np

OPTIMIZERS = ("adam", "sgd")


class SGD:
    """Gradient ascent with heavy-ball momentum: ``buf = momentum * buf + g``; ``x += lr * buf``."""

    def __init__(self, num_params: int, lr: float, momentum: float = 0.0):
        if not lr > 0:
            raise ValueError(f"lr must be > 0, got {lr}")
        if not 0.0 <= momentum < 1.0:
            raise ValueError(f"momentum must be in [0, 1), got {momentum}")
        self.lr, self.momentum = float(lr), float(momentum)
        self.buf = np.zeros(num_params)  # (n,) momentum buffer

    def step(self, x: np.ndarray, grad: np.ndarray) -> np.ndarray:
        """Return the new parameters after one ascent step along ``grad``."""
        buf = self.buf
        buf *= self.momentum  # (n,) buf = momentum * buf + grad
        buf += grad
        return x + self.lr * buf

    def reset_momentum(self) -> None:
        """Forget the gradients of earlier steps (the momentum buffer), as after a jump of ``x``."""
        self.buf[:] = 0.0

    def state_dict(self) -> dict[str, np.ndarray]:
        return {"buf": self.buf.copy()}

    def load_state_dict(self, state: dict[str, np.ndarray]) -> None:
        self.buf = _same_shape(state["buf"], self.buf, "buf")


class Adam:
    """Adam (Kingma & Ba 2015) for ascent: ``x += lr * m_hat / (sqrt(v_hat) + eps)``."""

    def __init__(self, num_params: int, lr: float, betas: tuple[float, float] = (0.9, 0.999),
                 eps: float = 1e-8):
        if not lr > 0:
            raise ValueError(f"lr must be > 0, got {lr}")
        b1, b2 = betas
        if not (0.0 <= b1 < 1.0 and 0.0 <= b2 < 1.0):
            raise ValueError(f"adam betas must be in [0, 1), got {betas}")
        self.lr, self.b1, self.b2, self.eps = float(lr), float(b1), float(b2), float(eps)
        self.m = np.zeros(num_params)  # (n,) first moment
        self.v = np.zeros(num_params)  # (n,) second moment
        self.t = 0  # steps taken (bias correction)

    def step(self, x: np.ndarray, grad: np.ndarray) -> np.ndarray:
        self.t += 1
        m, v = self.m, self.v
        tmp = (1.0 - self.b1) * grad  # (n,)
        m *= self.b1  # m = b1 * m + (1 - b1) * grad
        m += tmp
        np.multiply(grad, grad, out=tmp)
        tmp *= 1.0 - self.b2
        v *= self.b2  # v = b2 * v + (1 - b2) * (grad * grad)
        v += tmp
        denom = np.divide(v, 1.0 - self.b2**self.t)  # v_hat
        np.sqrt(denom, out=denom)
        denom += self.eps
        np.divide(m, 1.0 - self.b1**self.t, out=tmp)  # m_hat
        tmp *= self.lr  # lr * m_hat / (sqrt(v_hat) + eps)
        tmp /= denom
        return x + tmp

    def reset_momentum(self) -> None:
        """Forget the gradients of earlier steps (the first moment ``m``), as after a jump of ``x``: the
        next steps grow back from a tenth of their size (``m_hat`` rebuilds at rate ``1 - b1``); the
        second moment, the per-coordinate scale, is kept."""
        self.m[:] = 0.0

    def state_dict(self) -> dict[str, np.ndarray]:
        return {"m": self.m.copy(), "v": self.v.copy(), "t": np.array(self.t, dtype=np.int64)}

    def load_state_dict(self, state: dict[str, np.ndarray]) -> None:
        self.m = _same_shape(state["m"], self.m, "m")
        self.v = _same_shape(state["v"], self.v, "v")
        self.t = int(np.asarray(state["t"]))


def make_optimizer(name: str, num_params: int, lr: float, momentum: float = 0.0,
                   betas: tuple[float, float] = (0.9, 0.999), eps: float = 1e-8) -> SGD | Adam:
    """``"sgd"`` (uses ``momentum``) or ``"adam"`` (uses ``betas``, ``eps``)."""
    if name == "sgd":
        return SGD(num_params, lr, momentum)
    if name == "adam":
        return Adam(num_params, lr, betas, eps)
    raise ValueError(f"unknown optimizer {name!r}; choose one of {OPTIMIZERS}")


def _same_shape(value, like: np.ndarray, name: str) -> np.ndarray:
    arr = np.array(value, dtype=np.float64)
    if arr.shape != like.shape:
        raise ValueError(f"optimizer state {name!r} has shape {arr.shape}, expected {like.shape}")
    return arr
