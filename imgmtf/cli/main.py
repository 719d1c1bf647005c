"""The ``imgmtf`` command group and the commands registered in it (one
module per command beside this one)."""
from __future__ import annotations

import click

from . import fit, measure, report, reproduce, restore, scan, selftest, sensor, simulate


@click.group(context_settings={"help_option_names": ["-h", "--help"]})
@click.version_option(package_name="imgmtf", prog_name="imgmtf")   # read only when asked
@click.pass_context
def main(ctx):
    """Measure the MTF of imaging sensors from edge and pulse targets, and
    render exact synthetic chips with the generic pushbroom sensor."""
    from ..parallel import terminate_raises
    ctx.with_resource(terminate_raises())


#: every command, a module of its own beside this one: a new command is one
#: module and one entry here
COMMANDS = (simulate.simulate, sensor.sensor_command, fit.fit, measure.measure, scan.scan,
            report.report, reproduce.reproduce, selftest.selftest, restore.restore)
for _command in COMMANDS:
    main.add_command(_command)
