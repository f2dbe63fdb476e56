#!/usr/bin/env python3
"""Prints what a launch file starts, as roslaunch reads it (its own XML loader, with the arguments given):
one line per nodelet node `node NAME TYPE`, per remap `remap NAME FROM TO`, and per boolean ~passthrough parameter
`param NAME passthrough VALUE`. Used by launch_layout_test.cpp to compare launch/ret3d.launch with the stage table.
Usage: launch_nodes.py LAUNCH_FILE [name:=value ...]"""
import sys

import roslaunch.config
import roslaunch.xmlloader


def main():
    if len(sys.argv) < 2:
        sys.exit(__doc__)
    config = roslaunch.config.ROSLaunchConfig()
    roslaunch.xmlloader.XmlLoader(resolve_anon=False).load(sys.argv[1], config, argv=sys.argv[2:], verbose=False)
    for node in config.nodes:
        args = node.args.split()
        if node.package != 'nodelet' or len(args) < 2 or args[0] != 'load':
            continue
        name = node.name
        print('node', name, args[1])
        for source, target in node.remap_args:
            print('remap', name, source, target)
        key = '/' + name + '/passthrough'
        if key in config.params:
            print('param', name, 'passthrough', str(bool(config.params[key].value)).lower())


if __name__ == '__main__':
    main()
