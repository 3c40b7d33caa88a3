"""Spurious jumps in walks (rule 36's walk guard): 4 walking prompts x 16 samples (seed 3000+i, 120 frames, Earth,
shipped sampling settings); counts samples that jump by the checker's rule (flight >= 0.2 s, pelvis >= 15 cm).
Usage: python walk_probe.py MODEL..."""
import sys

from nonjump_probe import probe

PROMPTS = ["a person walks forward", "a person is walking straight ahead",
           "a person turns around and walks back", "a person walks in a circle"]

if __name__ == "__main__":
    probe(sys.argv[1:], PROMPTS, 16, 3000)
