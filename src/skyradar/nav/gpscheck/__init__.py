"""GPS integrity from a side-looking ground-scanning radar (Maas 2022, ch. 6).

``projection`` puts a frame's ground returns on a body-aligned ground grid; ``preprocess`` scales and
transforms radar and map images the thesis' ways; ``compare`` scores poses with SSIM (the thesis' 300-decoy
protocol); ``search`` estimates the pose offset that best aligns radar and map; ``monitor`` turns the
per-frame estimates into verdicts and an alert.
"""
