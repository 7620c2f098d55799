"""Per-round tensors of one observation read as one tensor along the frame axis, without joining them.

A phase trains on every committed round; ``torch.cat`` of their images or point clouds would hold
the largest inputs twice. ``FrameParts`` gathers only the frames a batch asks for.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence

import torch

ROW_COPY_LIMIT = 512
"""Up to this many frames a CPU gather copies row by row (about 2x faster for a batch of 84 px images)."""


class FrameParts:
    """Tensors of the same trailing shape, dtype and device, indexed as their concatenation on dim 0.

    Only integer-tensor indexing is supported, so nothing copies all frames by accident (``materialise``).
    """

    def __init__(self, parts: Sequence[torch.Tensor]) -> None:
        """Keeps ``parts`` uncopied; ``ValueError`` if empty or unlike in trailing shape, dtype, device."""
        if not parts:
            raise ValueError("FrameParts needs at least one tensor.")
        first = parts[0]
        for part in parts[1:]:
            if part.shape[1:] != first.shape[1:] or part.dtype != first.dtype or part.device != first.device:
                raise ValueError(
                    f"Cannot join a {part.dtype} {tuple(part.shape)} tensor on {part.device} with a "
                    f"{first.dtype} {tuple(first.shape)} one on {first.device}."
                )
        self.parts = list(parts)
        sizes = torch.tensor([len(part) for part in self.parts], dtype=torch.long)
        self.ends = torch.cumsum(sizes, 0)
        self.starts = self.ends - sizes

    def __len__(self) -> int:
        return int(self.ends[-1])

    @property
    def shape(self) -> torch.Size:
        """``(frames, *trailing)``, as the concatenated tensor's."""
        return torch.Size([len(self), *self.parts[0].shape[1:]])

    @property
    def dtype(self) -> torch.dtype:
        """The parts' dtype."""
        return self.parts[0].dtype

    @property
    def device(self) -> torch.device:
        """The parts' device."""
        return self.parts[0].device

    def __getitem__(self, index: torch.Tensor) -> torch.Tensor:
        """The frames at ``index`` (integer tensor of any shape, on any device), on the parts' device.

        Raises:
            TypeError: If ``index`` is not an integer tensor.
            IndexError: If an index is outside ``[-len(self), len(self))``.
        """
        if not isinstance(index, torch.Tensor) or index.dtype not in (torch.int32, torch.int64):
            raise TypeError(f"FrameParts is indexed with an integer tensor, got {type(index).__name__}.")
        flat = index.reshape(-1).to(device="cpu", dtype=torch.long)
        total = len(self)
        if len(flat) and (int(flat.min()) < -total or int(flat.max()) >= total):
            raise IndexError(f"Frame index out of range for {total} frames.")
        flat = torch.where(flat < 0, flat + total, flat)
        out = torch.empty((len(flat), *self.parts[0].shape[1:]), dtype=self.dtype, device=self.device)
        owner = torch.searchsorted(self.ends, flat, right=True)
        local = flat - self.starts[owner]
        if len(flat) <= ROW_COPY_LIMIT and self.device.type == "cpu":
            for row, (part_index, frame) in enumerate(zip(owner.tolist(), local.tolist(), strict=True)):
                out[row].copy_(self.parts[part_index][frame])
        else:
            for part_index in torch.unique(owner).tolist():
                rows = torch.nonzero(owner == part_index).squeeze(1)
                picked = torch.index_select(self.parts[part_index], 0, local[rows].to(self.device))
                out.index_copy_(0, rows.to(self.device), picked)
        return out.reshape(*index.shape, *out.shape[1:])

    def map(self, function: Callable[[torch.Tensor], torch.Tensor]) -> FrameParts:
        """``function`` applied to each part (e.g. normalisation), joined the same way."""
        return FrameParts([function(part) for part in self.parts])

    def materialise(self) -> torch.Tensor:
        """All frames as one new tensor (a full copy)."""
        return torch.cat(self.parts)


FrameTensor = torch.Tensor | FrameParts
"""A frame-indexed input: a tensor, or per-round tensors read as one (``FrameParts``)."""


def join_frames(tensors: Sequence[FrameTensor]) -> FrameTensor:
    """The frames of ``tensors`` one after the other, without a copy (``ValueError`` if none or unlike)."""
    pieces = [p for t in tensors for p in (t.parts if isinstance(t, FrameParts) else [t])]
    nonempty = [piece for piece in pieces if len(piece)] or pieces[:1]
    if len(nonempty) == 1:
        return nonempty[0]
    return FrameParts(nonempty)


def materialise(tensor: FrameTensor) -> torch.Tensor:
    """``tensor`` as one ``torch.Tensor`` (``FrameParts.materialise`` for parts)."""
    return tensor.materialise() if isinstance(tensor, FrameParts) else tensor
