#!/usr/bin/env python3
# A stand-in node for the launch comparison tests: never started, only located.
print("talker")
