#!/usr/bin/env python3
"""Writes the side-file corpus of tests/malformed_files.rs (run from this
directory; the files are committed, this script says how each was made)."""
import struct, zlib, json, base64

def png_chunk(name, data, crc=None):
    c = zlib.crc32(name + data) if crc is None else crc
    return struct.pack('>I', len(data)) + name + data + struct.pack('>I', c & 0xffffffff)

def png(w, h, raw, bad_crc=False):
    ihdr = struct.pack('>IIBBBBB', w, h, 8, 2, 0, 0, 0)
    idat = zlib.compress(raw)
    out = b'\x89PNG\r\n\x1a\n' + png_chunk(b'IHDR', ihdr)
    out += png_chunk(b'IDAT', idat, (zlib.crc32(b'IDAT' + idat) ^ 1) if bad_crc else None)
    return out + png_chunk(b'IEND', b'')

def write(name, data):
    open(name, 'wb').write(data if isinstance(data, bytes) else data.encode())

row = lambda w: b'\x00' + b'\x80' * (3 * w)
write('bad-crc.png', png(4, 4, row(4) * 4, bad_crc=True))
# A decompression bomb: 8000x8000 RGB claimed, a few hundred bytes of IDAT
# (the check is on the header, before any decoding).
write('bomb.png', png(8000, 8000, row(8000) * 4))
write('huge.png', png(200000, 200000, row(4)))
write('truncated.png', png(4, 4, row(4) * 4)[:40])
# TGA: RLE true colour 2x2, one run packet claiming 128 pixels.
tga_head = lambda t, w, h: bytes([0, 0, t]) + bytes(5) + struct.pack('<HHHHBB', 0, 0, w, h, 24, 0x20)
write('overrun.tga', tga_head(10, 2, 2) + bytes([0xff, 1, 2, 3]))
write('truncated-rle.tga', tga_head(10, 4, 4) + bytes([0x83, 1, 2, 3]))
write('huge.tga', tga_head(2, 65535, 65535) + bytes(30))
# PFM
write('huge.pfm', b'PF\n1000000 1000000\n-1\n' + bytes(16))
write('truncated.pfm', b'PF\n4 4\n-1\n' + bytes(16))
write('nan.pfm', b'PF\n2 1\n-1\n' + struct.pack('<6f', 1, float('nan'), 1, float('inf'), -1, 0.5))
write('bad-header.hdr', b'#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 0 +X 0\n')
write('huge.hdr', b'#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 60000 +X 60000\n' + bytes(64))
write('not-an-image.exr', b'v/1\x01' + bytes(60))
# .spd
write('odd-count.spd', '400 1\n500 1\n600\n')
write('words.spd', '400 one\n500 1\n')
write('nonfinite.spd', '400 1e999\n500 1\n')
write('decreasing.spd', '600 1\n500 0.5\n400 0.2\n')
write('empty.spd', '# nothing\n')
write('negative-wavelength.spd', '-400 1\n500 1\n')
# .bsdf: a header of 64 bytes, then nMu nodes, nMu^2 cdf, nMu^2 (offset, order), nCoeffs.
def bsdf(flags=1, n_mu=2, n_coeffs=4, m_max=1, channels=1, bases=1, eta=1.5, mu=(0.0, 1.0),
         cdf=None, pairs=None, a=None, magic=b'SCATFUN\x01', cut=None):
    h = magic + struct.pack('<9i', flags, n_mu, n_coeffs, m_max, channels, bases, 0, 0, 0)
    h += struct.pack('<f', eta) + bytes(64 - len(magic) - 36 - 4)
    cdf = cdf if cdf is not None else [0.0] * (len(mu) ** 2)
    pairs = pairs if pairs is not None else [(i, 1) for i in range(len(mu) ** 2)]
    a = a if a is not None else [0.1] * n_coeffs
    body = struct.pack('<%df' % len(mu), *mu) + struct.pack('<%df' % len(cdf), *cdf)
    body += b''.join(struct.pack('<ii', o, l) for o, l in pairs) + struct.pack('<%df' % len(a), *a)
    out = h + body
    return out[:cut] if cut else out
write('bad-magic.bsdf', bsdf(magic=b'SCATFOO\x01'))
write('truncated.bsdf', bsdf(cut=70))
write('huge-counts.bsdf', bsdf(n_mu=1 << 30, cut=80))
write('nan-coefficient.bsdf', bsdf(a=[0.1, float('nan'), 0.1, 0.1]))
write('offset-out-of-range.bsdf', bsdf(pairs=[(0, 1), (1, 1), (2, 1), (99, 1)]))
write('decreasing-nodes.bsdf', bsdf(mu=(1.0, 0.0)))
write('bad-flags.bsdf', bsdf(flags=2))
# Meshes
write('huge-count.ply', 'ply\nformat binary_little_endian 1.0\nelement vertex 4000000000\nproperty float x\nproperty float y\nproperty float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n' + '\0' * 64)
write('inconsistent.ply', 'ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nelement face 2\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n')
write('bad-index.obj', 'v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 99999999999\n')
def gltf(idx_type=5125, idx_count=3, pos_count=3, idx=(0, 1, 2), idx_fmt='<3I'):
    pos = struct.pack('<9f', 0, 0, 0, 1, 0, 0, 0, 1, 0)
    ib = struct.pack(idx_fmt, *idx)
    buf = pos + ib
    return json.dumps({"asset": {"version": "2.0"},
        "buffers": [{"byteLength": len(buf), "uri": "data:application/octet-stream;base64," + base64.b64encode(buf).decode()}],
        "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": 36}, {"buffer": 0, "byteOffset": 36, "byteLength": len(ib)}],
        "accessors": [{"bufferView": 0, "componentType": 5126, "count": pos_count, "type": "VEC3", "min": [0, 0, 0], "max": [1, 1, 0]},
                      {"bufferView": 1, "componentType": idx_type, "count": idx_count, "type": "SCALAR"}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "indices": 1}]}],
        "nodes": [{"mesh": 0}], "scenes": [{"nodes": [0]}], "scene": 0})
write('float-indices.gltf', gltf(idx_type=5126, idx_fmt='<3f'))
write('huge-count.gltf', gltf(idx_count=1000000000))
write('index-out-of-range.gltf', gltf(idx=(0, 1, 7)))
write('huge-positions.gltf', gltf(pos_count=2000000000))
# Lens files
write('words.dat', '# radius axpos N aperture\n35.0 5.0 1.6 twenty\n')
write('odd-count.dat', '35.0 5.0 1.6\n')
write('nonfinite.dat', '35.0 1e999 1.6 20\n0 5 0 10\n')
# Scene text that is not text
write('nul.pbrt', b'WorldBegin\n\x00\x00\x00\n')
write('huge-faces.ply', 'ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nelement face 3000000000\nproperty list uchar int vertex_indices\nend_header\n' + '\0' * 36 + '\3' + '\0' * 12)
write('huge-list.ply', 'ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nelement face 1\nproperty list uint int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n4000000000 0 1 2\n')
write('nan.spd', '400 nan\n500 1\n')
write('not-utf8.spd', b'400 \xff\xfe\n500 1\n')
write('zero-size.png', png(0, 0, b''))
write('zero-size.bsdf', bsdf(n_mu=0, mu=(), cdf=[], pairs=[], n_coeffs=0, a=[]))
