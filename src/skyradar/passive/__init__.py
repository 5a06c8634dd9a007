"""Passive bistatic radar with a rotating ATC primary radar as illuminator (Maas 2022, ch. 7).

Illuminator model, scene and IQ recording simulator (:mod:`.illuminator`, :mod:`.scene`,
:mod:`.simulate`); the processor (pulses, matched filter, MTI, CFAR, bistatic localisation) beside them.
Layer 3: imports only errors, units, geo, config, io and scene.
"""
