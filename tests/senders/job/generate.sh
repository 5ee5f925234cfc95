#!/bin/sh
# Regenerates the senders' laser job with a real laser CAM tool:
# svg2gcode (PyPI, "convert svg to gcode for GRBL v1.1 compatible diode
# laser engravers"), pinned, installed into target/senders/cam. The test
# does not need it: the .nc files are committed.
#   job.svg        drawing (make_svg.py authors it; the text "LA" is
#                  DejaVu Sans Bold converted to outlines with fontTools)
#   job-galvo.nc   50 x 35 mm, origin at the drawing's centre
#   job-gimbal.nc  the same scaled 1.6 (80 x 56 mm)
# svg2gcode 4.0.x does not run on Python 3.11 (an annotation names an
# unimported `List`), and 3.3.7's --selfcenter fails on a drawing without
# bitmaps, so the centre is given with --origin. Its header warns the cut
# is outside X[0,300] Y[0,400]: the board's origin is its centre.
set -eu
here=$(cd "$(dirname "$0")" && pwd)
cam=$here/../../../target/senders/cam
if [ ! -d "$cam/svg2gcode" ] || [ ! -d "$cam/fontTools" ]; then
    python3 -m pip install --quiet --target "$cam" svg2gcode==3.3.7 fonttools==4.55.3
fi
cd "$here"
PYTHONPATH=$cam python3 make_svg.py /usr/share/fonts/truetype/dejavu/DejaVuSans-Bold.ttf > job.svg
# HOME: no user configuration file (~/.config/svg2gcode.toml) applies.
run() { HOME=$here PYTHONPATH=$cam python3 "$cam/bin/svg2gcode" --nofill --no-constantburn --imagespeed 1200 "$@"; }
run --origin -25 -17.5 job.svg job-galvo.nc
run --scale 1.6 1.6 --origin -40 -28 job.svg job-gimbal.nc
