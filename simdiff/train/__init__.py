"""Training: backbone and SimDiff adapters, checkpoints, resume, DDP."""

from simdiff.train.config import OptimConfig, RunConfig, TrainConfig
from simdiff.train.data import MotionDataset, StepBatcher, TensorMotionDataset, synthetic_dataset
from simdiff.train.ema import EMA
from simdiff.train.trainer import Trainer

__all__ = ["EMA", "MotionDataset", "OptimConfig", "RunConfig", "StepBatcher", "TensorMotionDataset", "Trainer",
           "TrainConfig", "synthetic_dataset"]
