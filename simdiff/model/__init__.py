"""The diffusion network: MDM backbone, Sim Encoder, Motion Adapters, configs, condition and checkpoint I/O."""

from simdiff.model.adapter import MotionAdapter
from simdiff.model.backbone import MDMBackbone
from simdiff.model.checkpoint import (
    build_network,
    load_mdm_checkpoint,
    load_mdm_state_dict,
    load_pretrained,
    save_pretrained,
)
from simdiff.model.condition import Condition
from simdiff.model.config import BackboneConfig, ModelConfig, SimConfig, backbone_preset, config_from_dict
from simdiff.model.sim_encoder import SimEncoder
from simdiff.model.simdiff_net import SimDiffNet

__all__ = [
    "BackboneConfig", "Condition", "MDMBackbone", "ModelConfig", "MotionAdapter",
    "SimConfig", "SimDiffNet", "SimEncoder", "backbone_preset", "build_network", "config_from_dict",
    "load_mdm_checkpoint", "load_mdm_state_dict", "load_pretrained", "save_pretrained",
]
