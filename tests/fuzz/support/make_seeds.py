#!/usr/bin/env python3
"""Writes the seed corpora of the codec fuzz targets: real frames and
messages, most of them the golden vectors of the unit tests. The session
seeds of the scanner and cdn127_slave targets come from
fuzz_record_sessions instead. The files are committed; run this again after
changing a vector here.

Usage: make_seeds.py [tests/fuzz directory]
"""
import os
import sys

ROOT = sys.argv[1] if len(sys.argv) > 1 else os.path.join(os.path.dirname(__file__), "..")

SEEDS = {
    # [can id LE:4]
    "identifier": {
        "allocate_41e": [0x1E, 0x04, 0, 0],        # Group 2 msg 6 to MAC 3
        "explicit_response_41b": [0x1B, 0x04, 0, 0],  # Group 2 msg 3 from MAC 3
        "poll_response_3c1": [0xC1, 0x03, 0, 0],   # Group 1 msg 15 from MAC 1
        "group3_600": [0x00, 0x06, 0, 0],
        "group4_7ef": [0xEF, 0x07, 0, 0],          # offline ownership request
        "invalid_7f0": [0xF0, 0x07, 0, 0],
        "headers": [0x80, 0x0A, 0xC0, 0x81, 0x41, 0xFF],  # header and fragment bytes
    },
    # [selector: body format][message]
    "explicit_message": {
        # Allocate, unfragmented after the header: 4B 03 01 03 0A
        # (service Allocate, class 3, instance 1, choice explicit+poll, master MAC 10)
        "allocate_request": [0x00, 0x4B, 0x03, 0x01, 0x03, 0x0A],
        # Allocate success response: CB (4B|R/R) 00 (body format 8/8)
        "allocate_response": [0x00, 0xCB, 0x00],
        # Release: 4C 03 01 02 (poll)
        "release_request": [0x00, 0x4C, 0x03, 0x01, 0x02],
        # Get_Attribute_Single Identity 1 attribute 7, 8/8 and 16/16
        "get_product_name_8_8": [0x00, 0x0E, 0x01, 0x01, 0x07],
        "get_product_name_16_16": [0x02, 0x0E, 0x01, 0x00, 0x01, 0x00, 0x07],
        # Set_Attribute_Single Connection 2 attribute 9 (EPR) 0x0E0A
        "set_epr": [0x00, 0x10, 0x05, 0x02, 0x09, 0x0A, 0x0E],
        # Get product name response: 8E 06 'CDN127'
        "product_name_response": [0x00, 0x8E, 0x06] + list(b"CDN127"),
        # Error response: 94 0C (object state conflict) 01
        "error_response": [0x00, 0x94, 0x0C, 0x01],
        "error_response_no_additional": [0x00, 0x94, 0x08],
        # The 1760-DNET request message (first fragment's bytes and a tail)
        "dnet1760_request": [0x00, 0x32, 0x64, 0x01, 0x93, 0x05, 0x00, 0xEE, 0xFF],
    },
    # [max size][mode bit 0 clear][len][payload]...
    "explicit_reassembler": {
        # 1760-DNET response: 80 00 B2 11 22 33 44 55, then 80 81 0D 05 04
        "dnet1760_response": [0, 0x00, 8, 0x80, 0x00, 0xB2, 0x11, 0x22, 0x33, 0x44, 0x55,
                              5, 0x80, 0x81, 0x0D, 0x05, 0x04],
        # 1760-DNET request: 80 00 32 64 01 93 05 00, then 80 81 EE FF
        "dnet1760_request": [0, 0x00, 8, 0x80, 0x00, 0x32, 0x64, 0x01, 0x93, 0x05, 0x00,
                             4, 0x80, 0x81, 0xEE, 0xFF],
        # first, middle, middle repeated, last (counts 0, 1, 1, 2)
        "with_repeat": [0, 0x00, 8, 0x80, 0x00, 1, 2, 3, 4, 5, 6,
                        8, 0x80, 0x41, 7, 8, 9, 10, 11, 12,
                        8, 0x80, 0x41, 7, 8, 9, 10, 11, 12,
                        4, 0x80, 0x82, 19, 20],
        # overflow: limit 8 bytes
        "overflow": [8, 0x00, 8, 0x80, 0x00, 1, 2, 3, 4, 5, 6,
                     8, 0x80, 0x41, 7, 8, 9, 10, 11, 12],
        # sender to reassembler: a 20-byte message, no ack lost; then every 2nd lost
        "transfer": [0, 0x01] + list(range(1, 21)),
        "transfer_lossy": [0, 0x51] + list(range(1, 14)),
    },
    # [max size][mode][len][payload]...
    "io_reassembler": {
        # a 10-byte poll message in two fragments: 00 + 7 bytes, 81 + 3 bytes
        "two_fragments": [0, 0x00, 8, 0x00, 1, 2, 3, 4, 5, 6, 7, 4, 0x81, 8, 9, 10],
        # first, middle, last
        "three_fragments": [0, 0x00, 8, 0x00, 1, 2, 3, 4, 5, 6, 7,
                            8, 0x41, 8, 9, 10, 11, 12, 13, 14, 2, 0x82, 15],
        # split and join a 16-byte message; the same with the middle repeated
        "split": [0, 0x01] + list(range(16)),
        "split_repeat": [0, 0x03] + list(range(16)),
    },
    # [mac][7-byte payload]
    "duplicate_mac": {
        # request from port 127: 7F, vendor 59 (3B 00), serial 0x12345678
        "request": [0x01, 0x7F, 0x3B, 0x00, 0x78, 0x56, 0x34, 0x12],
        # response (bit 7), port 0; checked while online
        "response_online": [0x81, 0x80, 0x3B, 0x00, 0x01, 0x00, 0x01, 0x00],
        "request_online": [0x82, 0x00, 0x3B, 0x00, 0x02, 0x00, 0x01, 0x00],
    },
    "epath": {
        "class4_inst103_attr3": [0x20, 0x04, 0x24, 0x67, 0x30, 0x03],  # assembly 103 data
        "class4_inst1_attr3_16bit": [0x21, 0x04, 0x00, 0x25, 0x01, 0x00, 0x30, 0x03],
        "class4_inst104": [0x20, 0x04, 0x24, 0x68],
        "connection_point": [0x20, 0x04, 0x2C, 0x65],
        "empty": [],
        "class_32bit": [0x22, 0x00, 0x00, 0x01, 0x00, 0x24, 0x01],
    },
    "cip_string": {
        "short_cdn127": [0x06] + list(b"CDN127"),  # Identity product name
        "string_cdn127": [0x06, 0x00] + list(b"CDN127"),
        "short_padded": [0x08] + list(b"CDN127") + [0x20, 0x00],
        "short_empty": [0x00],
    },
    # [selector][mode DI DO AI AO mask][produced][consumed][payload]
    "poll_format": {
        # CDN127 preset (86, 8 DI, 8 DO, 2 AI, 1 AO): response DSUP DIN AIN AIN
        "cdn127_response": [0x00, 0x86, 8, 8, 2, 1, 0x00, 103, 104,
                            0x20, 0x1D, 0xFF, 0x0F, 0x00, 0x08],
        # CDN127 preset poll request: DOUT PAD AOUT (pump on, AOUT 0x0800)
        "cdn127_request": [0x00, 0x86, 8, 8, 2, 1, 0x00, 103, 104, 0x01, 0x00, 0x00, 0x08],
        # assembly 102: DIN PAD AIN AIN, the pad any value
        "assembly_102": [0x00, 0x86, 8, 8, 2, 1, 0x00, 102, 100, 0x1F, 0xA5, 0x34, 0x02, 0x00, 0x00],
        # CDN118 preset (81, 8 DI, 8 DO, 2 AI, 0 AO)
        "cdn118": [0x00, 0x81, 8, 8, 2, 0, 0x00, 103, 104, 0x80, 0x1F, 0x00, 0x00, 0x00, 0x00],
        # raw layouts: the CDN127 preset's, written out
        "raw_layouts": [0x01, 0x86, 8, 8, 2, 1, 0x00,
                        1, 1, 1, 8, 0, 2, 2, 6,   # response
                        0, 1, 1, 2, 1, 4,         # request
                        0x20, 0x1D, 0xFF, 0x0F, 0x00, 0x08],
    },
    # [selector][value]
    "device_info": {
        "revision": [0x00, 0x01, 0x05],
        "status_owned": [0x00, 0x01, 0x00],
        "serial_uint": [0x00, 0x34, 0x12],
        "serial_udint": [0x00, 0x78, 0x56, 0x34, 0x12],
        "product_name": [0x00, 0x06] + list(b"CDN127"),
        "state_operating": [0x00, 0x03],
        "exception_detail": [0x00, 0x03, 0xAA, 0xBB, 0xCC, 0x05, 0x07, 0x40, 0x10, 0x00, 0x80, 0x00],
        "warning_detail": [0x00, 0x02, 0x01, 0x00, 0x00, 0x01, 0x03],
        "detail_extra": [0x00, 0x00, 0x0A, 0x01, 0x00, 0x01, 0x00, 0x01, 0x00, 0x01, 0x00,
                         0xDE, 0xAD, 0x00],
    },
}


def main():
    for target, seeds in SEEDS.items():
        folder = os.path.join(ROOT, target, "corpus")
        os.makedirs(folder, exist_ok=True)
        for name, data in seeds.items():
            with open(os.path.join(folder, name), "wb") as f:
                f.write(bytes(data))


if __name__ == "__main__":
    main()
